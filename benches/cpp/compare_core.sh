#!/usr/bin/env bash
# The Rust core vs Pinocchio's C++ on the same UR5 and Panda models, and on floating-base robots
# (Talos, Solo-12, ANYmal with a free-flyer: issue 14) (benchmark only, never in CI).
#   pip install pin cmeel-eigen example-robot-data  # Pinocchio's headers ship in the `pin` wheel, Eigen's in cmeel-eigen
#   benches/cpp/compare_core.sh [ROBOT ...]          # floating robots of benches/common.py, default: all
# The floating robots travel as text: dump_tree.py writes kinedyn's compiled tree and one state of
# each (needs the built kinedyn package on PYTHONPATH, e.g. PYTHONPATH=python); both harnesses build
# their models from those files and print their rnea, crba and aba results, which must agree (with
# each other and with kinedyn's Python inverse_dynamics) to 1e-9 before any time is printed.
# Pinocchio is built header-only with -O3 -march=native (see the peer notes); the Rust `quick` bench with
# -C target-cpu=native in a separate target folder. Both report the fastest of many ~0.3 ms rounds;
# prints the ratio C++ time / Rust time.
set -euo pipefail
cd "$(dirname "$0")/../.."
SP=$(python -c "import site; print(site.getsitepackages()[0])")
INC="$SP/cmeel.prefix/include"
OUT=${KINEDYN_BENCH_DIR:-/tmp/kinedyn-cpp-bench}
mkdir -p "$OUT"
if [ ! -x "$OUT/pinocchio_dynamics" ] || [ benches/cpp/pinocchio_dynamics.cpp -nt "$OUT/pinocchio_dynamics" ] \
  || [ benches/cpp/harness.hpp -nt "$OUT/pinocchio_dynamics" ]; then
  echo "compiling Pinocchio (several minutes)..." >&2
  g++ -O3 -march=native -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -I"$INC" -I"$INC/eigen3" \
    benches/cpp/pinocchio_dynamics.cpp -o "$OUT/pinocchio_dynamics"
fi
RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$OUT/target" cargo bench -q -p kinedyn-core --bench quick --no-run 2>/dev/null
RUST=$(ls -t "$OUT"/target/release/deps/quick-* | grep -v '\.d$' | head -1)
PYTHONPATH=${PYTHONPATH:-python} python benches/cpp/dump_tree.py "$OUT/trees" "$@" > "$OUT/trees.txt"
mapfile -t TREES < "$OUT/trees.txt"
export KINEDYN_BENCH_TREES=$(IFS=:; echo "${TREES[*]}")
# the two sides alternate, KINEDYN_BENCH_ROUNDS (default 3) times each, and each keeps its fastest run (both report the minimum
# over rounds of ~0.3 ms): the machine's speed drifts by tens of percent from one run to the next
: > "$OUT/cpp.txt"; : > "$OUT/rust.txt"
for round in $(seq "${KINEDYN_BENCH_ROUNDS:-3}"); do
  "$OUT/pinocchio_dynamics" "${TREES[@]}" >> "$OUT/cpp.txt"
  "$RUST" --bench >> "$OUT/rust.txt"
done
python - "$OUT/cpp.txt" "$OUT/rust.txt" "${TREES[@]}" <<'PY'
import sys
def fastest(path):
    best, checks = {}, {}
    for line in open(path):
        key, *values = line.split()
        if "/check" in key:
            checks.setdefault(key, []).append([float(x) for x in values])  # one per round
        else:
            best[key] = min(best.get(key, float("inf")), float(values[0]))
    return best, checks
(cpp, cpp_checks), (rust, rust_checks) = fastest(sys.argv[1]), fastest(sys.argv[2])
# the floating robots: both sides computed on the same state; their results must agree to 1e-9
# (relative to the size of each number above 1), and the rnea with kinedyn's Python too
expected = {}
for tree in sys.argv[3:]:
    lines = dict(line.split(maxsplit=1) for line in open(tree) if line.startswith(("robot", "expect_rnea")))
    expected[lines["robot"].strip() + "/check_rnea"] = [[float(x) for x in lines["expect_rnea"].split()]]
    for alg in ("rnea", "crba", "aba"):
        key = lines["robot"].strip() + "/check_" + alg
        sides = [("Pinocchio C++", cpp_checks.get(key)), ("kinedyn-core", rust_checks.get(key))]
        if key in expected:
            sides.append(("kinedyn Python", expected[key]))
        for side, values in sides:
            if values is None:
                sys.exit(f"CHECK FAILED: {side} printed no {key} line")
        reference = sides[0][1][0]
        for side, rounds in sides:
            for values in rounds:
                if len(values) != len(reference):
                    sys.exit(f"CHECK FAILED: {key}: {side} has {len(values)} numbers, Pinocchio C++ {len(reference)}")
                worst = max(abs(x - y) / max(1.0, abs(y)) for x, y in zip(values, reference))
                if worst > 1e-9:
                    sys.exit(f"CHECK FAILED: {key}: {side} differs from Pinocchio C++ by {worst:.3g} (> 1e-9)")
        print(f"{key:28s} agree ({len(reference)} numbers, {', '.join(s for s, _ in sides)})")
print(f"{'':28s} {'Pinocchio C++':>14s} {'kinedyn-core':>13s}   speed-up")
for key, c in cpp.items():
    if key in rust:
        print(f"{key:28s} {c:11.0f} ns {rust[key]:10.0f} ns   {c / rust[key]:6.2f}x")
for key, r in rust.items():
    if key not in cpp and "free_flyer" in key:  # profiling lines of the Rust side alone (see quick.rs)
        print(f"{key:28s} {'':14s} {r:10.0f} ns")
# issue 17: per state of a 1024-state batch on one thread (quick.rs's bench_batches), beside
# Pinocchio's C++ per call of the same algorithm
print(f"{'batch, per state':28s} {'Pinocchio C++':>14s} {'kinedyn-core':>13s}   speed-up")
for key, r in rust.items():
    if "_batch_" in key:
        single = key.split("_batch_")[0]
        if single in cpp:
            print(f"{key:28s} {cpp[single]:11.1f} ns {r:10.1f} ns   {cpp[single] / r:6.2f}x")
PY
