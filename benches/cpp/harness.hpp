// What the C++ harnesses share (pinocchio_dynamics.cpp and pinocchio_codegen.cpp; benchmark only,
// never built in CI): the timer, and the tree files of dump_tree.py read into a pinocchio::Model.
// Include after any header that must come before Pinocchio's own (pinocchio/codegen/cppadcg.hpp does).
#pragma once
#include <pinocchio/multibody.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace harness {
using namespace pinocchio;
using Eigen::Matrix3d;
using Eigen::Vector3d;

// minimum over `rounds` runs of the mean time per call over ~0.3 ms, as the Rust side's
// `benches/quick.rs` measures: on a shared VM the fastest run is the least disturbed one
template <class F>
inline double min_ns(F&& f, int rounds = 400) {
  auto now = [] { return std::chrono::steady_clock::now(); };
  long reps = 0;
  for (auto start = now(); std::chrono::duration<double, std::micro>(now() - start).count() < 300; ++reps) f();
  double best = 1e300;
  for (int r = 0; r < rounds; ++r) {
    auto t0 = now();
    for (long k = 0; k < reps; ++k) f();
    best = std::min(best, std::chrono::duration<double, std::nano>(now() - t0).count() / reps);
  }
  return best;
}

// a robot read from a dump_tree.py file: the model and the state (q, v, a) to compute on
struct TreeFile {
  std::string name;
  Model model;
  Eigen::VectorXd q, v, a;
};

inline std::vector<double> numbers(std::istringstream& in, std::size_t count, const std::string& what) {
  std::vector<double> out(count);
  for (auto& x : out)
    if (!(in >> x)) throw std::runtime_error("too few numbers in " + what);
  return out;
}

inline Eigen::VectorXd vector_line(std::istream& file, const std::string& key, int size, const std::string& path) {
  std::string line, word;
  std::getline(file, line);
  std::istringstream in(line);
  in >> word;
  if (word != key) throw std::runtime_error(path + ": expected a '" + key + "' line, got '" + word + "'");
  auto x = numbers(in, size, path + " " + key);
  return Eigen::Map<Eigen::VectorXd>(x.data(), size);
}

inline JointModel joint_model(const std::string& kind, const Vector3d& axis, const std::string& path) {
  // axis-aligned types for +x, +y, +z (what Pinocchio's URDF parser chooses), unaligned otherwise
  auto is = [&](const Vector3d& e) { return (axis - e).norm() < 1e-12; };
  if (kind == "free") return JointModelFreeFlyer();
  if (kind == "spherical") return JointModelSpherical();  // q block (qx, qy, qz, qw), as kinedyn's
  if (kind == "revolute") {
    if (is(Vector3d::UnitX())) return JointModelRX();
    if (is(Vector3d::UnitY())) return JointModelRY();
    if (is(Vector3d::UnitZ())) return JointModelRZ();
    return JointModelRevoluteUnaligned(axis);
  }
  if (kind == "prismatic") {
    if (is(Vector3d::UnitX())) return JointModelPX();
    if (is(Vector3d::UnitY())) return JointModelPY();
    if (is(Vector3d::UnitZ())) return JointModelPZ();
    return JointModelPrismaticUnaligned(axis);
  }
  throw std::runtime_error(path + ": unknown joint kind '" + kind + "'");
}

inline TreeFile read_tree(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("cannot open " + path);
  TreeFile out;
  std::string line, word;
  int nq = 0, nv = 0, nbodies = 0;
  std::getline(file, line);
  std::istringstream(line) >> word >> out.name;
  std::getline(file, line);
  std::istringstream(line) >> word >> nq >> nv >> nbodies;
  std::getline(file, line);
  {
    std::istringstream in(line);
    in >> word;
    auto g = numbers(in, 3, path + " gravity");
    out.model.gravity.linear(Vector3d(g[0], g[1], g[2]));
  }
  std::vector<JointIndex> ids;
  for (int b = 0; b < nbodies; ++b) {
    std::getline(file, line);
    std::istringstream in(line);
    int parent = 0;
    std::string kind;
    in >> word >> parent >> kind;
    if (word != "body" || parent >= b) throw std::runtime_error(path + ": bad body line " + std::to_string(b));
    auto x = numbers(in, 3 + 9 + 3 + 1 + 3 + 9, path + " body " + std::to_string(b));
    Vector3d axis(x[0], x[1], x[2]);
    Matrix3d rot;
    rot << x[3], x[4], x[5], x[6], x[7], x[8], x[9], x[10], x[11];
    Vector3d trans(x[12], x[13], x[14]), com(x[16], x[17], x[18]);
    Matrix3d inertia;
    inertia << x[19], x[20], x[21], x[22], x[23], x[24], x[25], x[26], x[27];
    JointIndex parent_id = parent < 0 ? 0 : ids[parent];
    JointIndex id = out.model.addJoint(parent_id, joint_model(kind, axis, path), SE3(rot, trans), "joint" + std::to_string(b));
    out.model.appendBodyToJoint(id, Inertia(x[15], com, inertia), SE3::Identity());
    ids.push_back(id);
  }
  if (out.model.nq != nq || out.model.nv != nv)
    throw std::runtime_error(path + ": built nq, nv = " + std::to_string(out.model.nq) + ", " + std::to_string(out.model.nv) +
                             ", the file says " + std::to_string(nq) + ", " + std::to_string(nv));
  out.q = vector_line(file, "q", nq, path);
  out.v = vector_line(file, "v", nv, path);
  out.a = vector_line(file, "a", nv, path);
  return out;
}

inline void print_check(const std::string& key, const Eigen::VectorXd& x) {
  std::printf("%s", key.c_str());
  for (Eigen::Index i = 0; i < x.size(); ++i) std::printf(" %.17g", x[i]);
  std::printf("\n");
}

}  // namespace harness
