#!/usr/bin/env bash
# The Rust core's single calls beside Pinocchio's generated code (CppADCodeGen) on the same robots
# (issue 30, "the benchmark beside the anchor"). Benchmark only, never in CI.
#   pip install pin cmeel-eigen cmeel-cppad cmeel-cppadcodegen pybullet  # headers: Pinocchio's in `pin`,
#                                         # Eigen's, CppAD's and CppADCodeGen's in their cmeel wheels;
#                                         # the iiwa URDF from pybullet_data (example-robot-data has none)
#   PYTHONPATH=python benches/cpp/compare_codegen.sh [ROBOT ...]   # default: ur5 panda iiwa
# dump_tree.py writes each robot's compiled tree and one state; pinocchio_codegen.cpp builds
# Pinocchio's model from it, generates and compiles (gcc -O3 -march=native) one library per robot
# and algorithm, cached in $KINEDYN_BENCH_DIR/codegen (default /tmp/kinedyn-cpp-bench; build once,
# reused by later runs; KINEDYN_CODEGEN_REBUILD=1 builds again), checks every generated output
# against Pinocchio's generic algorithm, and times both; the Rust `quick` bench reads the same
# files. The generic results of the two sides must agree to 1e-9 (relative above 1) before any time
# is printed. The sides alternate KINEDYN_BENCH_ROUNDS times (default 5), each keeping its fastest
# run (the machine's speed drifts by tens of percent between runs).
#
# The table: ns per call, the ratio codegen ns / kinedyn ns (above 1: kinedyn faster), Pinocchio's
# generic C++ for scale, and the arithmetic floor: operations per call (+ - * / of the generated C,
# an FMA counted as two; kinedyn's generic algorithm counted by quick.rs's `flops`; the RNEA recorded
# for the robot by kinedyn_core::trace) against the machine's scalar peak, 4 double operations per
# cycle (two add and two multiply pipes, or two FMA) at the clock /proc/cpuinfo reports
# (KINEDYN_PEAK_OPS_PER_NS overrides it).
#
# Hook for a robot-specialised kinedyn (the JIT of issue 30): KINEDYN_BENCH_SPECIALIZED="COMMAND"
# runs COMMAND TREE_FILE... in every round beside the others; it prints "<robot>/<algorithm> <ns>"
# and "<robot>/check_<algorithm> <numbers>" lines as quick.rs does (algorithms rnea, crba,
# mass_matrix_inverse, aba, rnea_derivatives, aba_derivatives; any subset), checked like the
# others, and the table gains its column and ratio.
set -euo pipefail
cd "$(dirname "$0")/../.."
SP=$(python -c "import site; print(site.getsitepackages()[0])")
INC="$SP/cmeel.prefix/include"
for header in pinocchio/codegen/cppadcg-algo.hpp cppad/cg.hpp eigen3/Eigen/Core; do
  [ -e "$INC/$header" ] || { echo "missing $INC/$header: pip install pin cmeel-eigen cmeel-cppad cmeel-cppadcodegen" >&2; exit 2; }
done
OUT=${KINEDYN_BENCH_DIR:-/tmp/kinedyn-cpp-bench}
mkdir -p "$OUT/codegen"
BIN="$OUT/pinocchio_codegen"
# The harness itself at -O1: at -O3 its translation unit (six CodeGen classes on CppAD<CG<double>>)
# took over 15 CPU minutes and 10 GB of memory here and did not finish in 66 minutes on the shared
# machine. What is timed is not compiled here: the generated code is compiled by gcc at run time with
# -O3 -march=native. The harness's level shows only in the recording seconds and in the generic
# algorithm's times (R/A_pinocchio lines, left out of the table: compare_core.sh has those at -O3).
if [ ! -x "$BIN" ] || [ benches/cpp/pinocchio_codegen.cpp -nt "$BIN" ] || [ benches/cpp/harness.hpp -nt "$BIN" ]; then
  echo "compiling the CppADCodeGen harness (several minutes)..." >&2
  g++ ${KINEDYN_CODEGEN_HARNESS_OPT:--O1} -march=native -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -I"$INC" -I"$INC/eigen3" \
    benches/cpp/pinocchio_codegen.cpp -o "$BIN.new" -ldl
  mv "$BIN.new" "$BIN"
fi
RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$OUT/target" cargo bench -q -p kinedyn-core --bench quick --no-run 2>/dev/null
RUST=$(ls -t "$OUT"/target/release/deps/quick-* | grep -v '\.d$' | head -1)
[ $# -gt 0 ] || set -- ur5 panda iiwa
PYTHONPATH=${PYTHONPATH:-python} python benches/cpp/dump_tree.py "$OUT/codegen_trees" "$@" > "$OUT/codegen_trees.txt"
mapfile -t TREES < "$OUT/codegen_trees.txt"
export KINEDYN_BENCH_TREES=$(IFS=:; echo "${TREES[*]}") KINEDYN_BENCH_TREES_ONLY=1
# first run: builds what is not cached (its times are not kept)
"$BIN" "$OUT/codegen" "${TREES[@]}" > "$OUT/codegen_first.txt"
"$RUST" --bench flops > "$OUT/codegen_flops.txt"
: > "$OUT/codegen_cpp.txt"; : > "$OUT/codegen_rust.txt"; : > "$OUT/codegen_special.txt"
for round in $(seq "${KINEDYN_BENCH_ROUNDS:-5}"); do
  "$BIN" "$OUT/codegen" "${TREES[@]}" >> "$OUT/codegen_cpp.txt"
  "$RUST" --bench >> "$OUT/codegen_rust.txt"
  if [ -n "${KINEDYN_BENCH_SPECIALIZED:-}" ]; then
    $KINEDYN_BENCH_SPECIALIZED "${TREES[@]}" >> "$OUT/codegen_special.txt"
  fi
done
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
python benches/cpp/codegen_table.py "$OUT" "${TREES[@]}"
