// Fuzz-style robustness of the CAO reader: truncated, mutated and random inputs must give a
// model or a one-line error naming the file, never a crash or a hang (the sanitizer build
// catches memory and undefined-behaviour faults). Fixed seeds: failures reproduce.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "epichead/vision/cao_model.h"

using epichead::vision::CadModel;
using epichead::vision::parse_cao;

namespace {

const std::string kDir = std::string(EPICHEAD_TEST_DATA) + "/cao";

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> seeds() {
  std::vector<std::string> out;
  for (const char* f : {"cube.cao", "l_shape.cao", "cube_from_lines.cao", "wire_and_round.cao", "include_main.cao"}) {
    out.push_back(read_text(kDir + "/" + f));
  }
  out.push_back(read_text(std::string(EPICHEAD_SHARED_DATA) + "/teabox/model.cao"));
  for (const auto& s : out) REQUIRE(!s.empty());
  return out;
}

// The contract on any input: an error is one line naming the file, a model is consistent.
struct Stats {
  int models = 0, errors = 0;
};

void check_result(const std::string& text, Stats& stats) {
  auto m = parse_cao(text, "fuzz.cao", kDir);
  if (!m) {
    ++stats.errors;
    INFO(m.error());
    const bool names_file = m.error().starts_with("fuzz.cao:") || m.error().find(kDir) != std::string::npos;
    CHECK(names_file);
    CHECK(m.error().find('\n') == std::string::npos);
    return;
  }
  ++stats.models;
  const int nv = static_cast<int>(m->vertices.size());
  auto ok_vertex = [nv](int v) { return v >= 0 && v < nv; };
  bool consistent = true;
  for (const auto& v : m->vertices) consistent &= v.allFinite();
  for (const auto& f : m->faces) {
    const double n = f.normal_obj.norm();
    consistent &= std::isfinite(n) && (n == 0 || std::abs(n - 1) < 1e-9);
    consistent &= f.triangles.size() == (n == 0 ? 0 : f.vertices.size() - 2);
    for (const auto& t : f.triangles) consistent &= ok_vertex(t[0]) && ok_vertex(t[1]) && ok_vertex(t[2]);
  }
  const int nf = static_cast<int>(m->faces.size());
  for (const auto& e : m->edges) {
    consistent &= ok_vertex(e.v0) && ok_vertex(e.v1) && e.v0 != e.v1;
    for (int k = 0; k < 2; ++k) {
      consistent &= e.faces[k] >= -1 && e.faces[k] < nf && e.into_face[k].allFinite();
    }
  }
  const int ne = static_cast<int>(m->edges.size());
  for (const auto& p : m->parallel_pairs) {
    consistent &= p.edge_a >= 0 && p.edge_a < p.edge_b && p.edge_b < ne && std::isfinite(p.distance_m);
  }
  for (const auto& j : m->junctions) consistent &= ok_vertex(j.vertex) && j.edges.size() >= 2;
  for (const auto& c : m->circles) consistent &= c.radius_m > 0 && std::abs(c.normal_obj.norm() - 1) < 1e-9;
  INFO(text);
  CHECK(consistent);
}

std::vector<std::string> split_tokens(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string t;
  while (in >> t) out.push_back(t);
  return out;
}

std::string join(const std::vector<std::string>& tokens, std::mt19937& rng) {
  std::string out;
  for (const auto& t : tokens) {
    out += t;
    out += (rng() % 4 == 0) ? '\n' : ' ';
  }
  return out;
}

const std::vector<std::string> kNasty = {
    "-1", "0", "1", "2", "3", "10000000", "10000001", "2147483647", "2147483648", "-2147483649",
    "99999999999999999999", "1e308", "-1e308", "1e999", "1e-320", "nan", "-nan", "inf", "-inf", "+", "-",
    "0x10", "V1", "V2", "#", "//", "\"", "name=\"", "name=x", "=", "load(\"cube.cao\")", "load(\"",
    "load(\"include_main.cao\")", "load(\"nope.cao\", t=[1;2;3], tu=[0;0;9999deg])", "\xff", std::string(1, '\0')};

}  // namespace

TEST_CASE("every prefix of the valid files gives a model or a one-line error") {
  Stats stats;
  for (const std::string& text : seeds()) {
    for (std::size_t n = 0; n <= text.size(); ++n) check_result(text.substr(0, n), stats);
  }
  CHECK(stats.errors > 0);
  CHECK(stats.models > 0);  // e.g. prefixes ending after the faces (older file layout)
}

TEST_CASE("byte flips, token deletions, duplications and nasty values never crash the reader") {
  std::mt19937 rng(20240611);
  Stats stats;
  const auto texts = seeds();
  for (int round = 0; round < 400; ++round) {
    for (const std::string& seed : texts) {
      std::string text = seed;
      const int kind = static_cast<int>(rng() % 4);
      if (kind == 0) {  // byte flips
        const int flips = 1 + static_cast<int>(rng() % 4);
        for (int i = 0; i < flips; ++i) text[rng() % text.size()] = static_cast<char>(rng() % 256);
        check_result(text, stats);
        continue;
      }
      auto tokens = split_tokens(text);
      const std::size_t at = rng() % tokens.size();
      if (kind == 1) {
        tokens.erase(tokens.begin() + static_cast<long>(at));
      } else if (kind == 2) {
        tokens.insert(tokens.begin() + static_cast<long>(at), tokens[rng() % tokens.size()]);
      } else {
        tokens[at] = kNasty[rng() % kNasty.size()];
      }
      check_result(join(tokens, rng), stats);
    }
  }
  CHECK(stats.errors > 0);
  CHECK(stats.models > 0);
}

TEST_CASE("random models of small indices and coordinates give a consistent model or an error") {
  // Structurally valid files with random content: exercises the topology on self-intersecting,
  // repeated-vertex, collinear and non-manifold faces rather than the syntax checks.
  std::mt19937 rng(7);
  Stats stats;
  // Within kMaxModelExtentM (1e6 m): larger coordinates are refused by the reader.
  const char* coords[] = {"0", "1", "-1", "0.5", "2", "1e-9", "1e5"};
  // Neighbouring indices mostly differ, so that most files get past the syntax checks.
  auto other = [&rng](int points, int not_this) {
    const int v = static_cast<int>(rng() % points);
    return (v == not_this && rng() % 8 != 0) ? (v + 1) % points : v;
  };
  for (int round = 0; round < 1500; ++round) {
    const int points = 2 + static_cast<int>(rng() % 10);
    std::string text = "V1\n" + std::to_string(points) + "\n";
    for (int i = 0; i < points * 3; ++i) text += std::string(coords[rng() % 7]) + (i % 3 == 2 ? "\n" : " ");
    const int lines = static_cast<int>(rng() % 4);
    text += std::to_string(lines) + "\n";
    for (int i = 0; i < lines; ++i) {
      const int a = static_cast<int>(rng() % points);
      text += std::to_string(a) + " " + std::to_string(other(points, a)) + "\n";
    }
    text += "0\n";
    const int faces = static_cast<int>(rng() % 5);
    text += std::to_string(faces) + "\n";
    for (int f = 0; f < faces; ++f) {
      const int n = 3 + static_cast<int>(rng() % 8);
      std::vector<int> loop = {static_cast<int>(rng() % points)};
      while (static_cast<int>(loop.size()) < n) loop.push_back(other(points, loop.back()));
      if (loop.back() == loop.front() && rng() % 8 != 0) loop.back() = other(points, loop.front());
      text += std::to_string(n);
      for (int v : loop) text += " " + std::to_string(v);
      text += "\n";
    }
    if (rng() % 2 == 0) {
      const int a = static_cast<int>(rng() % points);
      text += "1\n" + std::to_string(a) + " " + std::to_string(other(points, a)) + " 0.1\n";
      text += "1\n0.1 " + std::to_string(rng() % points) + " " + std::to_string(rng() % points) + " " +
              std::to_string(rng() % points) + "\n";
    }
    check_result(text, stats);
  }
  CHECK(stats.errors > 0);
  CHECK(stats.models > 500);
}

TEST_CASE("random token soup never crashes the reader") {
  std::mt19937 rng(99);
  Stats stats;
  for (int round = 0; round < 2000; ++round) {
    std::vector<std::string> tokens = {"V1"};
    const int n = static_cast<int>(rng() % 60);
    for (int i = 0; i < n; ++i) {
      tokens.push_back(rng() % 3 == 0 ? kNasty[rng() % kNasty.size()] : std::to_string(rng() % 6));
    }
    check_result(join(tokens, rng), stats);
  }
  CHECK(stats.errors > 0);
}
