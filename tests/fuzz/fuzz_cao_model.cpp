// The CAO reader (cao_model.h) with load() of other files. The input is split at lines
// "@@file@@": the first part is main.cao, the others inc1.cao, inc2.cao, ... in the same folder
// (and sub/inc1.cao ... for loads from a subfolder), so includes, cycles and missing files are
// all reachable. Properties: a model or a one-line error, never a crash or a hang; a model has
// finite vertices and valid indices; to_cao writes it so that it reads back the same (points,
// faces, free lines, circles, cylinders).
#include <cmath>
#include <string>

#include "epichead/vision/cao_model.h"
#include "fuzz_support.h"

using namespace epichead::vision;
using epichead::fuzz::check;

namespace {

void check_consistent(const CadModel& m) {
  const int nv = static_cast<int>(m.vertices.size());
  auto ok = [nv](int v) { return v >= 0 && v < nv; };
  for (const auto& v : m.vertices) check(v.allFinite(), "a vertex is not finite");
  for (const auto& f : m.faces) {
    for (int v : f.vertices) check(ok(v), "a face refers to a missing vertex");
    for (const auto& t : f.triangles)
      for (int v : t) check(ok(v), "a triangle refers to a missing vertex");
    check(f.normal_obj.allFinite() && std::isfinite(f.offset_m), "a face plane is not finite");
  }
  for (const auto& e : m.edges) check(ok(e.v0) && ok(e.v1) && e.v0 != e.v1, "an edge is not two vertices");
  for (const auto& p : m.parallel_pairs) check(std::isfinite(p.distance_m), "a parallel pair distance is not finite");
  for (const auto& c : m.circles)
    check(c.centre_obj.allFinite() && c.normal_obj.allFinite() && std::isfinite(c.radius_m), "a circle is not finite");
  for (const auto& c : m.cylinders)
    check(c.axis_a_obj.allFinite() && c.axis_b_obj.allFinite() && std::isfinite(c.radius_m), "a cylinder is not finite");
}

int free_lines(const CadModel& m) {
  int n = 0;
  for (const auto& e : m.edges) n += e.face_count() == 0 && e.extra_faces == 0;
  return n;
}

void check_round_trip(const CadModel& a) {
  const std::string text = to_cao(a);
  auto b = parse_cao(text, "written.cao");
  check(b.has_value(), "to_cao wrote a model that does not read back: " + (b ? std::string() : b.error()));
  // Points for circles and cylinders may be appended after the model's own vertices.
  check(b->vertices.size() >= a.vertices.size(), "vertices lost");
  for (std::size_t i = 0; i < a.vertices.size(); ++i) check(a.vertices[i] == b->vertices[i], "a vertex moved");
  check(a.faces.size() == b->faces.size(), "face count changed");
  for (std::size_t i = 0; i < a.faces.size(); ++i) check(a.faces[i].vertices == b->faces[i].vertices, "a face changed");
  check(free_lines(a) == free_lines(*b), "free line count changed");
  check(a.circles.size() == b->circles.size(), "circle count changed");
  for (std::size_t i = 0; i < a.circles.size(); ++i) {
    check(a.circles[i].radius_m == b->circles[i].radius_m, "a circle radius changed");
    check(a.circles[i].centre_obj == b->circles[i].centre_obj, "a circle centre moved");
    check((a.circles[i].normal_obj - b->circles[i].normal_obj).norm() < 1e-6, "a circle normal turned");
  }
  check(a.cylinders.size() == b->cylinders.size(), "cylinder count changed");
  for (std::size_t i = 0; i < a.cylinders.size(); ++i) {
    check(a.cylinders[i].axis_a_obj == b->cylinders[i].axis_a_obj &&
              a.cylinders[i].axis_b_obj == b->cylinders[i].axis_b_obj &&
              a.cylinders[i].radius_m == b->cylinders[i].radius_m,
          "a cylinder changed");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  const auto parts = epichead::fuzz::split(epichead::fuzz::as_text(data, size), "@@file@@\n");
  const std::string main_path = scratch.write("main.cao", parts[0]);
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string name = "inc" + std::to_string(i) + ".cao";
    scratch.write(name, parts[i]);
    scratch.write("sub/" + name, parts[i]);
  }
  auto model = load_cao(main_path);
  if (!model) {
    epichead::fuzz::check_one_line(model.error(), "load_cao");
    return 0;
  }
  check_consistent(*model);
  check_round_trip(*model);
  return 0;
}
