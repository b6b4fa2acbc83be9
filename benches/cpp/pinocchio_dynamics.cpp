// Pinocchio's C++ dynamics on the same UR5 and Panda models as kinedyn-core's criterion bench
// (crates/kinedyn-core/benches/core.rs builds them from the same DH tables and numbers).
// Benchmark only, never built in CI: see compare_core.sh. Prints "<robot>/<algorithm> <ns>".
// Arguments: tree files written by dump_tree.py (floating-base robots, issue 14): each becomes a
// pinocchio::Model built joint by joint (JointModelFreeFlyer, axis-aligned or unaligned revolute and
// prismatic joints, as Pinocchio's URDF parser picks them); rnea, crba and aba are timed on the file's
// state and their results printed on "<robot>/check_<algorithm>" lines for compare_core.sh to compare
// with the Rust side's.
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>
#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness.hpp"

using namespace pinocchio;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using harness::min_ns;
using harness::print_check;
using harness::read_tree;
using harness::TreeFile;

static SE3 tx_rx(double a, double alpha) {  // rotation Rx(alpha), origin (a, 0, 0)
  return SE3(Eigen::AngleAxisd(alpha, Vector3d::UnitX()).toRotationMatrix(), Vector3d(a, 0, 0));
}
static SE3 tz(double d) { return SE3(Matrix3d::Identity(), Vector3d(0, 0, d)); }
// kinedyn's bench `body(mass, c, size)`: inertia k 1 about the centre of mass, k = m size^2 / 6
static Inertia body(double m, Vector3d c, double size) { return Inertia(m, c, Eigen::Matrix3d::Identity() * (m * size * size / 6.0)); }

static Model ur5() {
  const double PI2 = M_PI / 2;
  double dh[6][3] = {{0.089159, 0.0, PI2}, {0.0, -0.425, 0.0}, {0.0, -0.39225, 0.0}, {0.10915, 0.0, PI2}, {0.09465, 0.0, -PI2}, {0.0823, 0.0, 0.0}};
  double mass[6] = {3.7, 8.393, 2.275, 1.219, 1.219, 0.1879};
  double com[6][3] = {{0.0, -0.02561, 0.00193}, {0.2125, 0.0, 0.11336}, {0.15, 0.0, 0.0265}, {0.0, -0.0018, 0.01634}, {0.0, 0.0018, 0.01634}, {0.0, 0.0, -0.001159}};
  Model model;
  SE3 previous = SE3::Identity();
  JointIndex parent = 0;
  for (int i = 0; i < 6; ++i) {
    parent = model.addJoint(parent, JointModelRZ(), previous * tz(dh[i][0]), "j" + std::to_string(i));
    // centre of mass given in the DH link frame = body * Tz(d) Tx(a) Rx(alpha)
    model.appendBodyToJoint(parent, body(mass[i], Vector3d(com[i][0], com[i][1], com[i][2]), 0.1), tz(dh[i][0]) * tx_rx(dh[i][1], dh[i][2]));
    previous = tx_rx(dh[i][1], dh[i][2]);
  }
  return model;
}

static Model panda() {
  const double PI2 = M_PI / 2;
  double dh[7][3] = {{0.0, 0.333, 0.0}, {0.0, 0.0, -PI2}, {0.0, 0.316, PI2}, {0.0825, 0.0, PI2}, {-0.0825, 0.384, -PI2}, {0.0, 0.0, PI2}, {0.088, 0.0, PI2}};
  double mass[7] = {4.97, 0.646, 3.228, 3.587, 1.225, 1.666, 0.735};
  double com[7][3] = {{0.0035, 0.0029, -0.0762}, {-0.0032, -0.0714, 0.0042}, {0.0275, 0.0392, -0.0665}, {-0.0532, 0.1047, 0.0274}, {-0.0119, 0.0413, -0.0383}, {0.0601, -0.0141, -0.0104}, {0.0105, -0.0043, 0.0616}};
  Model model;
  JointIndex parent = 0;
  for (int i = 0; i < 7; ++i) {
    parent = model.addJoint(parent, JointModelRZ(), tx_rx(dh[i][0], dh[i][2]) * tz(dh[i][1]), "j" + std::to_string(i));
    model.appendBodyToJoint(parent, body(mass[i], Vector3d(com[i][0], com[i][1], com[i][2]), 0.12), SE3::Identity());
  }
  return model;
}

// rnea, crba and aba of a floating-base robot from a tree file, with their results for the check
static void bench_tree(const TreeFile& tree) {
  const Model& model = tree.model;
  Data data(model);
  const auto &q = tree.q, &v = tree.v, &a = tree.a;
  const std::string& name = tree.name;
  int n = model.nv;
  Eigen::VectorXd tau = rnea(model, data, q, v, a);
  print_check(name + "/check_rnea", tau);
  crba(model, data, q);
  Eigen::VectorXd upper(n * (n + 1) / 2);  // Pinocchio fills the upper triangle of M
  for (int i = 0, k = 0; i < n; ++i)
    for (int j = i; j < n; ++j) upper[k++] = data.M(i, j);
  print_check(name + "/check_crba", upper);
  print_check(name + "/check_aba", aba(model, data, q, v, tau));
  std::printf("%s/rnea %.1f\n", name.c_str(), min_ns([&] { rnea(model, data, q, v, a); }));
  std::printf("%s/crba %.1f\n", name.c_str(), min_ns([&] { crba(model, data, q); }));
  std::printf("%s/aba %.1f\n", name.c_str(), min_ns([&] { aba(model, data, q, v, tau); }));
}

int main(int argc, char** argv) {
  std::vector<TreeFile> trees;
  try {
    for (int k = 1; k < argc; ++k) trees.push_back(read_tree(argv[k]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pinocchio_dynamics: %s\n", e.what());
    return 2;
  }
  for (auto& [name, model] : {std::pair<std::string, Model>{"ur5", ur5()}, {"panda", panda()}}) {
    Data data(model);
    int n = model.nv;
    Eigen::VectorXd q(n), v(n), a(n);
    for (int i = 0; i < n; ++i) { q[i] = 0.3 + 0.7 * i; v[i] = 1.1 - 0.4 * i; a[i] = -0.5 + 0.3 * i; }
    Eigen::VectorXd tau = rnea(model, data, q, v, a);
    std::printf("%s/check_tau0 %.12f\n", name.c_str(), tau[0]);
    std::printf("%s/rnea %.1f\n", name.c_str(), min_ns([&] { rnea(model, data, q, v, a); }));
    std::printf("%s/crba %.1f\n", name.c_str(), min_ns([&] { crba(model, data, q); }));
    std::printf("%s/aba %.1f\n", name.c_str(), min_ns([&] { aba(model, data, q, v, tau); }));
    std::printf("%s/coriolis_matrix %.1f\n", name.c_str(), min_ns([&] { computeCoriolisMatrix(model, data, q, v); }));
    std::printf("%s/gravity_torque %.1f\n", name.c_str(), min_ns([&] { computeGeneralizedGravity(model, data, q); }));
    std::printf("%s/mass_matrix_inverse %.1f\n", name.c_str(), min_ns([&] { computeMinverse(model, data, q); }));
    // the derivatives into preallocated matrices, as a controller would call them
    Eigen::MatrixXd d1 = Eigen::MatrixXd::Zero(n, n), d2 = d1, d3 = d1;
    std::printf("%s/rnea_derivatives %.1f\n", name.c_str(), min_ns([&] { computeRNEADerivatives(model, data, q, v, a, d1, d2, d3); }));
    std::printf("%s/aba_derivatives %.1f\n", name.c_str(), min_ns([&] { computeABADerivatives(model, data, q, v, tau, d1, d2, d3); }));
  }
  for (const auto& tree : trees) bench_tree(tree);
  return 0;
}
