// Pinocchio's C++ constrained forward dynamics on the closed mechanisms of dump_loops.py's files
// (issue 27, "Tests and figures"), beside the Rust core's (crates/kinedyn-core/benches/loops.rs).
// Benchmark only, never built in CI: see compare_loops.sh.
//
// Each file's tree becomes a pinocchio::Model (harness.hpp); each loop a RigidConstraintModel between
// the two frames' joints and placements (CONTACT_3D for a point loop, CONTACT_6D for a weld; LOCAL:
// the accelerations do not depend on the axes the rows are written in). Pinocchio 4.1's
// `constraintDynamics` (the proximal solve of Carpentier, Budhiraja & Mansard, RSS 2021, on its
// sparse constrained Cholesky factorisation) runs at every closed state of the file with
// ProximalSettings(accuracy 1e-12, mu 1e-10, 100 iterations), as benches/bench_loops.py calls it
// from Python; `lcaba` (its loop-constrained articulated-body algorithm, Sathya & Carpentier 2024,
// mu 1e-6 as its documentation suggests) likewise when it agrees.
// Prints, per mechanism R:
//   R/check_qdd x...      constraintDynamics' qdd of every state (one after the other)
//   R/constraintDynamics NS   one call, the states taken in turn
//   R/lcaba NS            one call of lcaba, when its qdd agree with constraintDynamics' to 1e-9
//   R/lcaba_differs D     otherwise: the largest difference (relative above 1)
// Usage: pinocchio_loops FILE...
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/constrained-dynamics.hpp>
#include <pinocchio/algorithm/loop-constrained-aba.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "harness.hpp"

using namespace pinocchio;
using harness::min_ns;
using harness::print_check;
using harness::read_tree;
using harness::TreeFile;
typedef std::vector<RigidConstraintModel, Eigen::aligned_allocator<RigidConstraintModel>> Models;
typedef std::vector<RigidConstraintData, Eigen::aligned_allocator<RigidConstraintData>> Datas;

struct State {
  Eigen::VectorXd q, v, tau;
};

// the lines after the tree: loops (tree body b is Pinocchio's joint b + 1, the base joint 0) and states
static void read_loops(const std::string& path, const Model& model, Models& loops, std::vector<State>& states) {
  std::ifstream file(path);
  std::string line, word;
  while (std::getline(file, line)) {
    std::istringstream in(line);
    in >> word;
    if (word == "loop") {
      std::string kind;
      in >> kind;
      JointIndex joint[2];
      SE3 placement[2];
      for (int side = 0; side < 2; ++side) {
        int body = 0;
        in >> body;
        auto x = harness::numbers(in, 12, path + " loop");
        Eigen::Matrix3d rot;
        rot << x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8];
        joint[side] = JointIndex(body + 1);
        placement[side] = SE3(rot, Eigen::Vector3d(x[9], x[10], x[11]));
      }
      if (kind != "point" && kind != "weld") throw std::runtime_error(path + ": unknown loop kind '" + kind + "'");
      loops.emplace_back(kind == "point" ? CONTACT_3D : CONTACT_6D, model, joint[0], placement[0], joint[1], placement[1], LOCAL);
    } else if (word == "state") {
      auto x = harness::numbers(in, model.nq + 3 * model.nv, path + " state");
      State s;
      s.q = Eigen::Map<Eigen::VectorXd>(x.data(), model.nq);
      s.v = Eigen::Map<Eigen::VectorXd>(x.data() + model.nq, model.nv);
      s.tau = Eigen::Map<Eigen::VectorXd>(x.data() + model.nq + model.nv, model.nv);
      states.push_back(s);
    }
  }
  if (loops.empty() || states.empty()) throw std::runtime_error(path + ": no loops or no states (a dump_loops.py file?)");
}

static void bench(const std::string& path) {
  TreeFile tree = read_tree(path);
  const Model& model = tree.model;
  const std::string& name = tree.name;
  Models loops;
  std::vector<State> states;
  read_loops(path, model, loops, states);
  Data data(model);
  Datas datas;
  for (const auto& l : loops) datas.emplace_back(l);
  initConstraintDynamics(model, data, loops, datas);
  ProximalSettings settings(1e-12, 1e-10, 100);
  Eigen::VectorXd all(model.nv * states.size());
  for (std::size_t k = 0; k < states.size(); ++k)
    all.segment(model.nv * k, model.nv) = constraintDynamics(model, data, states[k].q, states[k].v, states[k].tau, loops, datas, settings);
  print_check(name + "/check_qdd", all);
  std::size_t k = 0;
  std::printf("%s/constraintDynamics %.1f\n", name.c_str(), min_ns([&] {
                const State& s = states[k];
                k = (k + 1) % states.size();
                constraintDynamics(model, data, s.q, s.v, s.tau, loops, datas, settings);
              }));

  Data lc_data(model);
  Datas lc_datas;
  for (const auto& l : loops) lc_datas.emplace_back(l);
  computeJointMinimalOrdering(model, lc_data, loops);
  ProximalSettings lc_settings(1e-12, 1e-6, 100);
  double worst = 0;
  for (std::size_t j = 0; j < states.size(); ++j) {
    const Eigen::VectorXd& qdd = lcaba(model, lc_data, states[j].q, states[j].v, states[j].tau, loops, lc_datas, lc_settings);
    for (int i = 0; i < model.nv; ++i) {
      double want = all[model.nv * j + i];
      worst = std::max(worst, std::abs(qdd[i] - want) / std::max(1.0, std::abs(want)));
    }
  }
  if (!(worst <= 1e-9)) {
    std::printf("%s/lcaba_differs %.3g\n", name.c_str(), worst);
    return;
  }
  k = 0;
  std::printf("%s/lcaba %.1f\n", name.c_str(), min_ns([&] {
                const State& s = states[k];
                k = (k + 1) % states.size();
                lcaba(model, lc_data, s.q, s.v, s.tau, loops, lc_datas, lc_settings);
              }));
}

int main(int argc, char** argv) {
  try {
    for (int k = 1; k < argc; ++k) bench(argv[k]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pinocchio_loops: %s\n", e.what());
    return 2;
  }
  return 0;
}
