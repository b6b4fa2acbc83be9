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

using namespace pinocchio;
using Eigen::Matrix3d;
using Eigen::Vector3d;

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

// minimum over `rounds` runs of the mean time per call over ~0.3 ms, as the Rust side's
// `benches/quick.rs` measures: on a shared VM the fastest run is the least disturbed one
template <class F>
static double min_ns(F&& f, int rounds = 400) {
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

static std::vector<double> numbers(std::istringstream& in, std::size_t count, const std::string& what) {
  std::vector<double> out(count);
  for (auto& x : out)
    if (!(in >> x)) throw std::runtime_error("too few numbers in " + what);
  return out;
}

static Eigen::VectorXd vector_line(std::istream& file, const std::string& key, int size, const std::string& path) {
  std::string line, word;
  std::getline(file, line);
  std::istringstream in(line);
  in >> word;
  if (word != key) throw std::runtime_error(path + ": expected a '" + key + "' line, got '" + word + "'");
  auto x = numbers(in, size, path + " " + key);
  return Eigen::Map<Eigen::VectorXd>(x.data(), size);
}

static JointModel joint_model(const std::string& kind, const Vector3d& axis, const std::string& path) {
  // axis-aligned types for +x, +y, +z (what Pinocchio's URDF parser chooses), unaligned otherwise
  auto is = [&](const Vector3d& e) { return (axis - e).norm() < 1e-12; };
  if (kind == "free") return JointModelFreeFlyer();
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

static TreeFile read_tree(const std::string& path) {
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

static void print_check(const std::string& key, const Eigen::VectorXd& x) {
  std::printf("%s", key.c_str());
  for (Eigen::Index i = 0; i < x.size(); ++i) std::printf(" %.17g", x[i]);
  std::printf("\n");
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
