#!/usr/bin/env bash
# The Rust core vs Pinocchio's C++ on the same UR5 and Panda models (benchmark only, never in CI).
#   pip install pin cmeel-eigen      # Pinocchio's headers ship in the `pin` wheel, Eigen's in cmeel-eigen
#   benches/cpp/compare_core.sh
# Pinocchio is built header-only with -O3 -march=native (see the peer notes); the Rust `quick` bench with
# -C target-cpu=native in a separate target folder. Both report the fastest of many ~0.3 ms rounds;
# prints the ratio C++ time / Rust time.
set -euo pipefail
cd "$(dirname "$0")/../.."
SP=$(python -c "import site; print(site.getsitepackages()[0])")
INC="$SP/cmeel.prefix/include"
OUT=${KINEDYN_BENCH_DIR:-/tmp/kinedyn-cpp-bench}
mkdir -p "$OUT"
if [ ! -x "$OUT/pinocchio_dynamics" ] || [ benches/cpp/pinocchio_dynamics.cpp -nt "$OUT/pinocchio_dynamics" ]; then
  echo "compiling Pinocchio (several minutes)..." >&2
  g++ -O3 -march=native -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -I"$INC" -I"$INC/eigen3" \
    benches/cpp/pinocchio_dynamics.cpp -o "$OUT/pinocchio_dynamics"
fi
RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$OUT/target" cargo bench -q -p kinedyn-core --bench quick --no-run 2>/dev/null
RUST=$(ls -t "$OUT"/target/release/deps/quick-* | grep -v '\.d$' | head -1)
# the two sides alternate, three times each, and each keeps its fastest run (both report the minimum
# over rounds of ~0.3 ms): the machine's speed drifts by tens of percent from one run to the next
: > "$OUT/cpp.txt"; : > "$OUT/rust.txt"
for round in 1 2 3; do
  "$OUT/pinocchio_dynamics" | grep -v /check >> "$OUT/cpp.txt"
  "$RUST" --bench >> "$OUT/rust.txt"
done
python - "$OUT/cpp.txt" "$OUT/rust.txt" <<'PY'
import sys
def fastest(path):
    best = {}
    for line in open(path):
        key, ns = line.split()
        best[key] = min(best.get(key, float("inf")), float(ns))
    return best
cpp, rust = fastest(sys.argv[1]), fastest(sys.argv[2])
print(f"{'':28s} {'Pinocchio C++':>14s} {'kinedyn-core':>13s}   speed-up")
for key, c in cpp.items():
    if key in rust:
        print(f"{key:28s} {c:11.0f} ns {rust[key]:10.0f} ns   {c / rust[key]:6.2f}x")
PY
