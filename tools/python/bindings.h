#pragma once
// Shared pieces of the Python module's binding files (epichead_module.cpp): the exception
// every bad input becomes, and the conversions between numpy arrays and the library's types.
// The bindings only convert and call: every computation is the C++ libraries'.
#include <expected>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace epichead::python {

namespace py = pybind11;

// epichead.Error (a ValueError) in Python: the library's error text, which names the file.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The value of an expected, or epichead.Error with its reason.
template <typename T>
T value_or_raise(std::expected<T, std::string>&& e) {
  if (!e) throw Error(e.error());
  return std::move(*e);
}
inline void value_or_raise(std::expected<void, std::string>&& e) {
  if (!e) throw Error(e.error());
}

// A pose as a 4x4 homogeneous matrix (numpy) and back; the matrix must be a rigid transform.
Eigen::Matrix4d pose_matrix(const Eigen::Isometry3d& pose);
Eigen::Isometry3d pose_from_matrix(const Eigen::Matrix4d& m, const char* what);

// A JSON value as Python objects: objects -> dict, arrays -> list, numbers, strings, None.
py::object to_python(const nlohmann::json& j);

void bind_vision(py::module_& m);
void bind_tracker(py::module_& m);
void bind_fusion(py::module_& m);
void bind_replay(py::module_& m);

}  // namespace epichead::python
