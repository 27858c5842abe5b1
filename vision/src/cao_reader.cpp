// ViSP's CAO model format (V1): the reader, with load() includes (the writer: cao_writer.cpp).
//
// ViSP reads a CAO file as a stream of tokens (with `#` comment lines), so tokens may be spread
// over lines freely; we do the same but keep the line of every token for messages. Sections, in
// order: points, lines, faces from lines, faces from points, cylinders (`p1 p2 radius`), circles
// (`radius centre p1 p2`). The last two may be missing in old files. `load("f.cao")` lines come
// right after the version, each file's indices refer to its own points, and its points are
// appended after those already loaded (ViSP's behaviour).
#include "epichead/vision/cao_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string_view>
#include <system_error>

#include <Eigen/Geometry>

#include "cao_build.h"
#include "cao_text.h"

namespace epichead::vision {
namespace {

namespace fs = std::filesystem;
using namespace cao_text;  // the tokens, numbers and file reading of cao_text.h

// How errors state the bound on coordinates, radii and translations.
const std::string kExtentText = "the 1e6 m a physical model can have";

constexpr long long kMaxCount = 10'000'000;  // per section; real models are far below
constexpr int kMaxLoadDepth = 16;
constexpr int kMaxLoadedFiles = 1000;

// Files being loaded, outermost first: canonical path (to find cycles) and name for messages.
struct LoadChain {
  std::vector<std::string> ids;
  std::vector<std::string> names;
};

struct Accumulator {
  RawModel raw;
  detail::RawSources where;
  int files = 0;
};

// Reads one CAO file's text into the accumulator, recursing into load()s.
class Parser {
 public:
  Parser(std::string_view text, std::string name, fs::path dir, const Eigen::Isometry3d& model_T_file,
         LoadChain& chain, Accumulator& acc)
      : lex_(text), name_(std::move(name)), dir_(std::move(dir)), model_T_file_(model_T_file), chain_(chain),
        acc_(acc) {}

  std::expected<void, std::string> run() {
    if (auto ok = read_version(); !ok) return ok;
    if (auto ok = read_loads(); !ok) return ok;
    if (auto ok = read_points(); !ok) return ok;
    if (auto ok = read_lines(); !ok) return ok;
    if (auto ok = read_faces_from_lines(); !ok) return ok;
    if (auto ok = read_faces_from_points(); !ok) return ok;
    if (value_token_peek().end()) return {};  // files older than cylinders end here
    if (auto ok = read_cylinders(); !ok) return ok;
    if (value_token_peek().end()) return {};  // ... or before circles
    if (auto ok = read_circles(); !ok) return ok;
    if (const Token t = value_token(); !t.end()) return expected(t, "end of file");
    return {};
  }

 private:
  using Fail = std::unexpected<std::string>;

  std::string at(int line) const { return name_ + ":" + std::to_string(line); }
  std::string at(const Token& t) const { return at(t.line); }
  Fail fail(const Token& t, const std::string& what) const { return Fail(at(t) + ": " + what); }
  Fail expected(const Token& t, const std::string& what) const {
    return fail(t, "expected " + what + ", got " + shown(t));
  }

  // The next token that is not a `key=value` attribute (ViSP's name=..., useLod=...; others
  // are skipped too, so newer files still load).
  Token value_token() {
    for (;;) {
      const Token t = lex_.next();
      if (t.end() || t.text.find('=') == std::string_view::npos) return t;
    }
  }
  Token value_token_peek() {
    for (;;) {
      const Token t = lex_.peek();
      if (t.end() || t.text.find('=') == std::string_view::npos) return t;
      lex_.next();
    }
  }

  // `what` names the expected value; it is called only to write a message, so that reading
  // a large file builds no strings.
  template <class What>
  std::expected<long long, std::string> read_integer(const What& what, Token& t) {
    t = value_token();
    long long value = 0;
    bool overflow = false;
    if (!parse_integer(t.text, value, overflow)) return expected(t, what());
    if (overflow) return fail(t, what() + " " + shown(t) + " out of range");
    return value;
  }

  std::expected<long long, std::string> read_count(const std::string& what) {
    Token t;
    auto n = read_integer([&] { return what; }, t);
    if (n && (*n < 0 || *n > kMaxCount)) {
      return fail(t, what + " " + std::to_string(*n) + " out of range (0 to " + std::to_string(kMaxCount) + ")");
    }
    return n;
  }

  // An index into a list of `count` items of this file (ViSP: indices are local to the file).
  std::expected<int, std::string> read_index(const char* kind, std::size_t count, Token& t) {
    auto i = read_integer([kind] { return std::string(kind) + " index"; }, t);
    if (!i) return std::unexpected(i.error());
    if (*i < 0 || static_cast<unsigned long long>(*i) >= count) {
      return fail(t, std::string(kind) + " index " + std::to_string(*i) + " out of range (" +
                         std::to_string(count) + " " + kind + "s)");
    }
    return static_cast<int>(*i);
  }

  std::expected<int, std::string> read_point(Token& t) {
    auto i = read_index("point", points_, t);
    if (!i) return i;
    return *i + point_offset_;
  }
  // N point indices in a row (a line's ends, a cylinder's axis, a circle's centre and plane),
  // with their tokens for messages.
  template <std::size_t N>
  std::expected<void, std::string> read_point_indices(std::array<Token, N>& t, std::array<int, N>& idx) {
    for (std::size_t k = 0; k < N; ++k) {
      auto p = read_point(t[k]);
      if (!p) return std::unexpected(p.error());
      idx[k] = *p;
    }
    return {};
  }


  template <class What>
  std::expected<double, std::string> read_number(const What& what, Token& t) {
    t = value_token();
    double value = 0;
    if (!parse_number(t.text, value)) return expected(t, what() + " (a finite number)");
    return value;
  }

  std::expected<double, std::string> read_radius() {
    Token t;
    auto r = read_number([] { return std::string("radius"); }, t);
    if (r && !(*r > 0)) return fail(t, "radius must be > 0, got " + shown(t));
    if (r && *r > kMaxModelExtentM) return fail(t, "radius " + shown(t) + " is beyond " + kExtentText);
    return r;
  }

  std::expected<void, std::string> read_version() {
    Token t = value_token();
    std::string_view v = t.text;
    if (v == "V" || v == "v") {  // ViSP reads 'V' and then a number
      t = value_token();
      v = t.text;
    } else if (v.starts_with('V') || v.starts_with('v')) {
      v.remove_prefix(1);
    } else {
      return expected(t, "version 'V1'");
    }
    // V2 adds two image coordinates to every point, which we skip.
    if (v == "1") version_ = 1;
    else if (v == "2") version_ = 2;
    else return expected(t, "version 'V1'");
    return {};
  }

  std::expected<void, std::string> read_loads() {
    for (Token t = lex_.peek(); t.text.starts_with("load"); t = lex_.peek()) {
      const std::string_view line = lex_.take_line(t);
      if (auto ok = load(line, t); !ok) return ok;
    }
    return {};
  }

  // load("file.cao"[, t=[x;y;z]][, tu=[rx;ry;rz]]): the file's points map into this one by
  // (tu, t), tu an axis-angle vector, angles in rad unless suffixed "deg" (ViSP's syntax).
  std::expected<void, std::string> load(std::string_view line, const Token& t) {
    std::string_view s = trim(line.substr(4));
    if (!s.starts_with('(')) return fail(t, "expected load(\"file.cao\")");
    s.remove_prefix(1);
    s = trim(s);
    if (!s.starts_with('"')) return fail(t, "expected a quoted file name in load()");
    const std::size_t quote = s.find('"', 1);
    if (quote == std::string_view::npos) return fail(t, "missing closing '\"' in load()");
    const std::string file(s.substr(1, quote - 1));
    s.remove_prefix(quote + 1);
    const std::size_t close = s.find(')');
    if (close == std::string_view::npos) return fail(t, "missing ')' closing load()");
    std::string_view params = s.substr(0, close);
    Eigen::Vector3d trans = Eigen::Vector3d::Zero(), tu = Eigen::Vector3d::Zero();
    while (!trim(params).empty()) {
      params = trim(params);
      if (!params.starts_with(',')) return fail(t, "expected ',' between load() parameters");
      params.remove_prefix(1);
      const std::size_t comma = params.find(',');  // vector values are split by ';'
      const std::string_view param = trim(params.substr(0, comma));
      params = comma == std::string_view::npos ? std::string_view{} : params.substr(comma);
      Eigen::Vector3d* target = param.starts_with("t=") ? &trans : param.starts_with("tu=") ? &tu : nullptr;
      if (!target) continue;  // unknown key=value: skipped
      if (!parse_vector(param.substr(param.find('=') + 1), target == &tu, *target)) {
        return fail(t, "expected t=[x;y;z] or tu=[rx;ry;rz] in load(), got '" +
                           std::string(param.substr(0, 60)) + "'");
      }
    }
    if (trans.cwiseAbs().maxCoeff() > kMaxModelExtentM) {
      char shown_t[96];
      std::snprintf(shown_t, sizeof shown_t, "t=[%g;%g;%g]", trans.x(), trans.y(), trans.z());
      return fail(t, "load() translation " + std::string(shown_t) + " is beyond " + kExtentText);
    }
    Eigen::Isometry3d file_T_child = Eigen::Isometry3d::Identity();
    const double angle = tu.norm();
    if (angle > 0) file_T_child.linear() = Eigen::AngleAxisd(angle, tu / angle).toRotationMatrix();
    file_T_child.translation() = trans;

    const fs::path given(file);
    const fs::path path = (given.is_absolute() ? given : dir_ / given).lexically_normal();
    std::error_code ec;
    const std::string id = fs::weakly_canonical(path, ec).string();
    for (std::size_t i = 0; i < chain_.ids.size(); ++i) {
      if (chain_.ids[i] != id) continue;
      std::string cycle;
      for (std::size_t k = i; k < chain_.names.size(); ++k) cycle += chain_.names[k] + " -> ";
      return fail(t, "load() cycle: " + cycle + path.string());
    }
    if (static_cast<int>(chain_.ids.size()) >= kMaxLoadDepth) {
      return fail(t, "load() nested deeper than " + std::to_string(kMaxLoadDepth) + " files");
    }
    if (++acc_.files > kMaxLoadedFiles) {
      return fail(t, "more than " + std::to_string(kMaxLoadedFiles) + " files loaded");
    }
    auto text = read_file(path);
    if (!text) return fail(t, "load(): " + text.error());
    chain_.ids.push_back(id);
    chain_.names.push_back(path.string());
    Parser child(*text, path.string(), path.parent_path(), model_T_file_ * file_T_child, chain_, acc_);
    auto ok = child.run();
    chain_.ids.pop_back();
    chain_.names.pop_back();
    return ok;
  }

  // "[a;b;c]", each value optionally suffixed "rad" or (for angles) "deg".
  static bool parse_vector(std::string_view s, bool angles, Eigen::Vector3d& out) {
    s = trim(s);
    if (!s.starts_with('[') || !s.ends_with(']')) return false;
    s = s.substr(1, s.size() - 2);
    for (int i = 0; i < 3; ++i) {
      const std::size_t semi = s.find(';');
      if ((i < 2) != (semi != std::string_view::npos)) return false;
      std::string_view v = trim(s.substr(0, semi));
      s = semi == std::string_view::npos ? std::string_view{} : s.substr(semi + 1);
      double scale = 1;
      if (angles && v.ends_with("deg")) {
        v.remove_suffix(3);
        scale = std::numbers::pi / 180;
      } else if (angles && v.ends_with("rad")) {
        v.remove_suffix(3);
      }
      if (!parse_number(trim(v), out[i])) return false;
      out[i] *= scale;
    }
    return true;
  }

  std::expected<void, std::string> read_points() {
    auto n = read_count("number of points");
    if (!n) return std::unexpected(n.error());
    point_offset_ = static_cast<int>(acc_.raw.vertices.size());
    if (static_cast<long long>(point_offset_) + *n > kMaxCount) {
      return Fail(at(lex_.line()) + ": more than " + std::to_string(kMaxCount) + " points in all");
    }
    for (long long k = 0; k < *n; ++k) {
      Eigen::Vector3d p;
      Token t;
      for (int c = 0; c < 3; ++c) {
        const auto what = [&] { return std::string("coordinate ") + "XYZ"[c] + " of point " + std::to_string(k); };
        auto v = read_number(what, t);
        if (!v) return std::unexpected(v.error());
        if (std::abs(*v) > kMaxModelExtentM) return fail(t, what() + " " + shown(t) + " is beyond " + kExtentText);
        p[c] = *v;
      }
      for (int c = 0; c < (version_ == 2 ? 2 : 0); ++c) {
        if (auto v = read_integer([&] { return "image coordinate of point " + std::to_string(k); }, t); !v) {
          return std::unexpected(v.error());
        }
      }
      const Eigen::Vector3d p_model = model_T_file_ * p;
      if (!(p_model.cwiseAbs().maxCoeff() <= kMaxModelExtentM))
        return fail(t, "point " + std::to_string(k) + " lies beyond " + kExtentText + " once moved by the load() transforms");
      acc_.raw.vertices.push_back(p_model);
    }
    points_ = static_cast<std::size_t>(*n);
    return {};
  }

  std::expected<void, std::string> read_lines() {
    auto n = read_count("number of lines");
    if (!n) return std::unexpected(n.error());
    for (long long k = 0; k < *n; ++k) {
      std::array<Token, 2> t;
      std::array<int, 2> p;
      if (auto ok = read_point_indices(t, p); !ok) return ok;
      if (p[0] == p[1] || acc_.raw.vertices[p[0]] == acc_.raw.vertices[p[1]]) {
        return fail(t[1], "line has equal end points (" + std::string(t[0].text) + " " + std::string(t[1].text) + ")");
      }
      lines_.push_back(p);
      acc_.raw.free_lines.push_back({p[0], p[1]});  // merged into face edges they lie on
      acc_.where.lines.push_back(at(t[0]));
    }
    return {};
  }

  std::expected<long long, std::string> read_face_size(const char* of, Token& t) {
    auto n = read_integer([of] { return std::string("number of ") + of + " of a face"; }, t);
    if (!n) return n;
    if (*n < 3 || *n > kMaxCount) {
      return fail(t, "face has " + std::to_string(*n) + " " + of + ", needs 3 to " + std::to_string(kMaxCount));
    }
    return n;
  }

  // A face given by lines in loop order, each in either direction, chained into a vertex loop.
  std::expected<void, std::string> read_faces_from_lines() {
    auto n = read_count("number of faces from lines");
    if (!n) return std::unexpected(n.error());
    std::vector<int> ids;
    std::vector<Token> tokens;
    for (long long k = 0; k < *n; ++k) {
      Token head;
      auto m = read_face_size("lines", head);
      if (!m) return std::unexpected(m.error());
      ids.clear();
      tokens.clear();
      for (long long i = 0; i < *m; ++i) {
        Token t;
        auto l = read_index("line", lines_.size(), t);
        if (!l) return std::unexpected(l.error());
        ids.push_back(*l);
        tokens.push_back(t);
      }
      const auto& first = lines_[ids[0]];
      const auto& second = lines_[ids[1]];
      // Start at the end of the first line that the second one does not touch.
      const bool first_reversed = first[0] == second[0] || first[0] == second[1];
      if (first_reversed && (first[1] == second[0] || first[1] == second[1])) {
        return fail(tokens[1], "face: line " + std::string(tokens[1].text) + " has the same end points as line " +
                                   std::string(tokens[0].text));
      }
      const int start = first_reversed ? first[1] : first[0];
      std::vector<int> loop;
      int at_vertex = start;
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const auto& line = lines_[ids[i]];
        if (line[0] != at_vertex && line[1] != at_vertex) {
          return fail(tokens[i], "face: line " + std::string(tokens[i].text) + " does not continue from line " +
                                     std::string(tokens[i == 0 ? 0 : i - 1].text) + " (lines must form a closed loop)");
        }
        loop.push_back(at_vertex);
        at_vertex = line[0] == at_vertex ? line[1] : line[0];
      }
      if (at_vertex != start) {
        return fail(tokens.back(), "face: its lines do not close (line " + std::string(tokens.back().text) +
                                       " does not end where line " + std::string(tokens[0].text) + " starts)");
      }
      acc_.raw.face_loops.push_back(std::move(loop));
      acc_.where.faces.push_back(at(head));
    }
    return {};
  }

  std::expected<void, std::string> read_faces_from_points() {
    auto n = read_count("number of faces from points");
    if (!n) return std::unexpected(n.error());
    for (long long k = 0; k < *n; ++k) {
      Token head;
      auto m = read_face_size("points", head);
      if (!m) return std::unexpected(m.error());
      std::vector<int> loop;
      for (long long i = 0; i < *m; ++i) {
        Token t;
        auto v = read_point(t);
        if (!v) return std::unexpected(v.error());
        if (!loop.empty() && loop.back() == *v) {
          return fail(t, "face has point " + std::string(t.text) + " twice in a row");
        }
        loop.push_back(*v);
      }
      if (loop.front() == loop.back()) {
        return fail(head, "face ends on its first point " + std::to_string(loop.front() - point_offset_) +
                              " (do not repeat it)");
      }
      acc_.raw.face_loops.push_back(std::move(loop));
      acc_.where.faces.push_back(at(head));
    }
    return {};
  }

  std::expected<void, std::string> read_cylinders() {
    auto n = read_count("number of cylinders");
    if (!n) return std::unexpected(n.error());
    for (long long k = 0; k < *n; ++k) {
      std::array<Token, 2> t;
      std::array<int, 2> p;
      if (auto ok = read_point_indices(t, p); !ok) return ok;
      auto r = read_radius();
      if (!r) return std::unexpected(r.error());
      ModelCylinder c;
      c.axis_a_obj = acc_.raw.vertices[p[0]];
      c.axis_b_obj = acc_.raw.vertices[p[1]];
      c.radius_m = *r;
      if (c.axis_a_obj == c.axis_b_obj) return fail(t[1], "cylinder axis points are equal");
      acc_.raw.cylinders.push_back(c);
      acc_.where.cylinders.push_back(at(t[0]));
    }
    return {};
  }

  // ViSP: radius, centre point, two more points of the circle's plane. The normal is
  // (p1 - centre) x (p2 - centre), so the point order sets which side the circle faces.
  std::expected<void, std::string> read_circles() {
    auto n = read_count("number of circles");
    if (!n) return std::unexpected(n.error());
    for (long long k = 0; k < *n; ++k) {
      const Token head = value_token_peek();
      auto r = read_radius();
      if (!r) return std::unexpected(r.error());
      std::array<Token, 3> t;
      std::array<int, 3> p;  // centre, two points of the plane
      if (auto ok = read_point_indices(t, p); !ok) return ok;
      const Eigen::Vector3d& centre = acc_.raw.vertices[p[0]];
      const Eigen::Vector3d normal = (acc_.raw.vertices[p[1]] - centre).cross(acc_.raw.vertices[p[2]] - centre);
      if (!(normal.norm() > 0) || !normal.allFinite()) {
        return fail(t[2], "circle's plane points are collinear with its centre");
      }
      acc_.raw.circles.push_back({centre, normal.normalized(), *r});
      acc_.where.circles.push_back(at(head));
    }
    return {};
  }

  Lexer lex_;
  std::string name_;
  fs::path dir_;
  Eigen::Isometry3d model_T_file_;
  LoadChain& chain_;
  Accumulator& acc_;
  int version_ = 1;
  int point_offset_ = 0;   // this file's point 0 in the model
  std::size_t points_ = 0;  // points in this file
  std::vector<std::array<int, 2>> lines_;  // this file's lines, model point indices
};

std::expected<CadModel, std::string> parse_top(const std::string& text, const std::string& name,
                                               const fs::path& dir, const std::string& id) {
  LoadChain chain;
  chain.ids.push_back(id);
  chain.names.push_back(name);
  Accumulator acc;
  Parser parser(text, name, dir, Eigen::Isometry3d::Identity(), chain, acc);
  if (auto ok = parser.run(); !ok) return std::unexpected(ok.error());
  return detail::build_model_located(acc.raw, name, &acc.where);
}

}  // namespace

std::expected<CadModel, std::string> load_cao(const std::string& path) {
  auto text = read_file(path);
  if (!text) return std::unexpected(text.error());
  std::error_code ec;
  const fs::path p(path);
  return parse_top(*text, path, p.parent_path().empty() ? fs::path(".") : p.parent_path(),
                   fs::weakly_canonical(p, ec).string());
}

std::expected<CadModel, std::string> parse_cao(const std::string& text, const std::string& name,
                                               const std::string& base_dir) {
  std::error_code ec;
  const fs::path dir = base_dir.empty() ? fs::path(".") : fs::path(base_dir);
  return parse_top(text, name, dir, fs::weakly_canonical(dir / name, ec).string());
}

}  // namespace epichead::vision
