// Pinocchio's generated code (CppADCodeGen) beside its generic C++, on the robots of dump_tree.py's
// tree files (issue 30, "the benchmark beside the anchor"). Benchmark only, never built in CI: see
// compare_codegen.sh.
//
// For each tree file and each algorithm (rnea, crba, mass_matrix_inverse, aba, rnea_derivatives,
// aba_derivatives) Pinocchio's CodeGen* class records the algorithm on CppAD<CG<double>> for that one
// robot, CppADCodeGen writes it as C and gcc compiles it (-O3 -march=native) into a shared library
// cached under the output folder (KINEDYN_BENCH_DIR/codegen): a later run loads it without recording
// again (delete the folder, or set KINEDYN_CODEGEN_REBUILD=1, to build afresh). Before any time is
// printed every output of the generated code is checked against Pinocchio's generic algorithm on the
// file's state (1e-9, relative above 1); a difference stops the program (exit 3).
//
// Prints, per robot R and algorithm A:
//   R/check_A x...        the generic algorithm's results (for the comparison with the Rust side):
//                         rnea: tau; crba, mass_matrix_inverse: the upper triangle, row by row;
//                         aba: qdd at tau = rnea(q, v, a); rnea_derivatives: dtau/dq then dtau/dv,
//                         aba_derivatives: dqdd/dq then dqdd/dv (row-major, n x n each)
//   R/A_codegen NS        one call of the generated function (inputs and outputs as flat arrays)
//   R/A_pinocchio NS      one call of the generic algorithm (the derivatives into preallocated matrices)
//   R/A_codegen_build S1 S2 SOURCES   seconds recording (CppAD tape + optimisation) and seconds
//                         generating and compiling, as measured when the library was built; the
//                         generated C sources' folder
// Usage: pinocchio_codegen OUT_DIR TREE_FILE...
#include <pinocchio/codegen/cppadcg-algo.hpp>  // before Pinocchio's other headers (harness.hpp)

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "harness.hpp"

using namespace pinocchio;
using harness::min_ns;
using harness::print_check;
using harness::read_tree;
using harness::TreeFile;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A CodeGen* class with access to what the benchmark needs: the recording without the Jacobian
// (rnea and aba build one by default; the derivatives are timed through their own classes), and the
// library built with chosen compiler flags and its sources kept.
template <class Gen>
struct Open : Gen {
  using Gen::Gen;
  void forward_only() { this->build_jacobian = false; }
  void build(const std::string& sources) {
    CppAD::cg::GccCompiler<double> gcc("/usr/bin/gcc");
    gcc.setCompileFlags({"-O3", "-march=native"});
    gcc.setCompileLibFlags({"-O3", "-march=native", "-shared", "-rdynamic"});
    gcc.setSourcesFolder(sources);
    gcc.setSaveToDiskFirst(true);
    gcc.setTemporaryFolder(sources + "/tmp");
    this->dynamicLibManager_ptr->createDynamicLibrary(gcc, false);
  }
};

static bool exists(const std::string& path) {
  struct stat s;
  return stat(path.c_str(), &s) == 0;
}

static double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// One generated function, loaded from its library (built first when it is not cached).
struct Generated {
  std::unique_ptr<CppAD::cg::LinuxDynamicLib<double>> lib;
  std::unique_ptr<CppAD::cg::GenericModel<double>> fn;
  std::string build_line;

  void eval(const Eigen::VectorXd& x, Eigen::VectorXd& y) {
    fn->ForwardZero(CppAD::cg::ArrayView<const double>(x.data(), x.size()), CppAD::cg::ArrayView<double>(y.data(), y.size()));
  }
};

template <class Gen>
static Generated generated(const Model& model, const std::string& dir, const std::string& alg) {
  // CodeGenBase names the library "<library_name>_<model.name>" and the function "<function_name>"
  const std::string prefix = dir + "/" + alg, path = prefix + "_" + model.name + ".so";
  const std::string sources = dir + "/src_" + model.name + "_" + alg, info = prefix + "_" + model.name + ".build";
  const char* rebuild = std::getenv("KINEDYN_CODEGEN_REBUILD");
  if (!exists(path) || (rebuild && std::string(rebuild) == "1")) {
    std::fprintf(stderr, "generating %s for %s...\n", alg.c_str(), model.name.c_str());
    mkdir(sources.c_str(), 0755);
    mkdir((sources + "/tmp").c_str(), 0755);
    auto t0 = std::chrono::steady_clock::now();
    Open<Gen> gen(model, alg, prefix);
    gen.forward_only();
    gen.initLib();  // buildMap: the algorithm recorded on CppAD<CG<double>>, the tape optimised
    double record = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    gen.build(sources);
    double compile = seconds_since(t0);
    std::ofstream(info) << record << " " << compile << " " << sources << "\n";
  }
  Generated out;
  out.lib.reset(new CppAD::cg::LinuxDynamicLib<double>(path));
  out.fn = out.lib->model(alg);
  if (!out.fn) throw std::runtime_error(path + " has no model '" + alg + "'");
  std::ifstream in(info);
  std::getline(in, out.build_line);
  return out;
}

static Eigen::VectorXd upper(const Eigen::MatrixXd& m) {
  Eigen::VectorXd out(m.rows() * (m.rows() + 1) / 2);
  for (Eigen::Index i = 0, k = 0; i < m.rows(); ++i)
    for (Eigen::Index j = i; j < m.cols(); ++j) out[k++] = m(i, j);
  return out;
}

static Eigen::VectorXd row_major(const Eigen::MatrixXd& m) {
  RowMatrix r = m;
  return Eigen::Map<const Eigen::VectorXd>(r.data(), r.size());
}

static Eigen::VectorXd concat(std::initializer_list<Eigen::VectorXd> parts) {
  Eigen::Index size = 0;
  for (const auto& p : parts) size += p.size();
  Eigen::VectorXd out(size);
  Eigen::Index at = 0;
  for (const auto& p : parts) out.segment(at, p.size()) = p, at += p.size();
  return out;
}

// the generated outputs against the generic ones, entry by entry (1e-9, relative above 1)
static void check(const std::string& key, const Eigen::VectorXd& got, const Eigen::VectorXd& want) {
  if (got.size() != want.size()) {
    std::fprintf(stderr, "CHECK FAILED: %s: %ld numbers generated, %ld generic\n", key.c_str(), (long)got.size(), (long)want.size());
    std::exit(3);
  }
  double worst = 0;
  for (Eigen::Index i = 0; i < got.size(); ++i) worst = std::max(worst, std::abs(got[i] - want[i]) / std::max(1.0, std::abs(want[i])));
  if (!(worst <= 1e-9)) {
    std::fprintf(stderr, "CHECK FAILED: %s: the generated code differs from the generic algorithm by %.3g (> 1e-9)\n", key.c_str(), worst);
    std::exit(3);
  }
}

static void bench_tree(TreeFile& tree, const std::string& dir) {
  Model& model = tree.model;
  model.name = tree.name;
  Data data(model);
  const auto &q = tree.q, &v = tree.v, &a = tree.a;
  const std::string& name = tree.name;
  const int n = model.nv;
  auto report = [&](const std::string& alg, Generated& g, double generic_ns) {
    std::printf("%s/%s_pinocchio %.1f\n", name.c_str(), alg.c_str(), generic_ns);
    std::printf("%s/%s_codegen_build %s\n", name.c_str(), alg.c_str(), g.build_line.c_str());
  };
  auto timed = [&](const std::string& alg, Generated& g, const Eigen::VectorXd& x, Eigen::Index outputs) {
    Eigen::VectorXd y(outputs);
    std::printf("%s/%s_codegen %.1f\n", name.c_str(), alg.c_str(), min_ns([&] { g.eval(x, y); }));
  };
  const Eigen::VectorXd qva = concat({q, v, a});

  // generic results, checked lines first
  Eigen::VectorXd tau = rnea(model, data, q, v, a);
  print_check(name + "/check_rnea", tau);
  crba(model, data, q);
  Eigen::MatrixXd mass = data.M;
  print_check(name + "/check_crba", upper(mass));
  computeMinverse(model, data, q);
  Eigen::MatrixXd minv = data.Minv;
  print_check(name + "/check_mass_matrix_inverse", upper(minv));
  Eigen::VectorXd qdd = aba(model, data, q, v, tau);
  print_check(name + "/check_aba", qdd);
  Eigen::MatrixXd d1 = Eigen::MatrixXd::Zero(n, n), d2 = d1, d3 = d1;
  computeRNEADerivatives(model, data, q, v, a, d1, d2, d3);
  const Eigen::VectorXd drnea = concat({row_major(d1), row_major(d2)}), drnea_m = upper(d3);
  print_check(name + "/check_rnea_derivatives", drnea);
  computeABADerivatives(model, data, q, v, tau, d1, d2, d3);
  const Eigen::VectorXd daba = concat({row_major(d1), row_major(d2)}), daba_minv = upper(d3);
  print_check(name + "/check_aba_derivatives", daba);
  const Eigen::VectorXd qvt = concat({q, v, tau});

  // the generated functions: built or loaded, checked, timed
  auto g_rnea = generated<CodeGenRNEA<double>>(model, dir, "rnea");
  auto g_crba = generated<CodeGenCRBA<double>>(model, dir, "crba");
  auto g_minv = generated<CodeGenMinv<double>>(model, dir, "mass_matrix_inverse");
  auto g_aba = generated<CodeGenABA<double>>(model, dir, "aba");
  auto g_drnea = generated<CodeGenRNEADerivatives<double>>(model, dir, "rnea_derivatives");
  auto g_daba = generated<CodeGenABADerivatives<double>>(model, dir, "aba_derivatives");
  Eigen::VectorXd y;
  y.resize(n), g_rnea.eval(qva, y), check(name + "/rnea", y, tau);
  y.resize(n * (n + 1) / 2), g_crba.eval(q, y), check(name + "/crba", y, upper(mass));
  g_minv.eval(q, y), check(name + "/mass_matrix_inverse", y, upper(minv));
  y.resize(n), g_aba.eval(qvt, y), check(name + "/aba", y, qdd);
  // the derivatives: three row-major n x n blocks; the third (M, M^-1) compared on its upper triangle
  auto three = [&](Generated& g, const Eigen::VectorXd& x, const std::string& key, const Eigen::VectorXd& first_two, const Eigen::VectorXd& third) {
    Eigen::VectorXd out(3 * n * n);
    g.eval(x, out);
    check(key, out.head(2 * n * n), first_two);
    RowMatrix last = Eigen::Map<RowMatrix>(out.data() + 2 * n * n, n, n);
    check(key + " (third block)", upper(last), third);
  };
  three(g_drnea, qva, name + "/rnea_derivatives", drnea, drnea_m);
  three(g_daba, qvt, name + "/aba_derivatives", daba, daba_minv);

  timed("rnea", g_rnea, qva, n);
  report("rnea", g_rnea, min_ns([&] { rnea(model, data, q, v, a); }));
  timed("crba", g_crba, q, n * (n + 1) / 2);
  report("crba", g_crba, min_ns([&] { crba(model, data, q); }));
  timed("mass_matrix_inverse", g_minv, q, n * (n + 1) / 2);
  report("mass_matrix_inverse", g_minv, min_ns([&] { computeMinverse(model, data, q); }));
  timed("aba", g_aba, qvt, n);
  report("aba", g_aba, min_ns([&] { aba(model, data, q, v, tau); }));
  timed("rnea_derivatives", g_drnea, qva, 3 * n * n);
  report("rnea_derivatives", g_drnea, min_ns([&] { computeRNEADerivatives(model, data, q, v, a, d1, d2, d3); }));
  timed("aba_derivatives", g_daba, qvt, 3 * n * n);
  report("aba_derivatives", g_daba, min_ns([&] { computeABADerivatives(model, data, q, v, tau, d1, d2, d3); }));
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: pinocchio_codegen OUT_DIR TREE_FILE...\n");
    return 2;
  }
  const std::string dir = argv[1];
  mkdir(dir.c_str(), 0755);
  std::vector<TreeFile> trees;
  try {
    for (int k = 2; k < argc; ++k) trees.push_back(read_tree(argv[k]));
    for (auto& tree : trees) bench_tree(tree, dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pinocchio_codegen: %s\n", e.what());
    return 2;
  }
  return 0;
}
