#!/usr/bin/env bash
# Constrained forward dynamics of closed mechanisms: the Rust core beside Pinocchio's C++
# `constraintDynamics` (and `lcaba`) on the same models and closed states (issue 27, "Tests and
# figures"). Benchmark only, never in CI.
#   pip install pin cmeel-eigen                    # Pinocchio's headers in `pin`, Eigen's in cmeel-eigen
#   PYTHONPATH=python benches/cpp/compare_loops.sh [NAME ...]  # default: four_bar five_bar delta pushrod_leg
# dump_loops.py writes each mechanism of examples/robots (tree, loops, 64 closed states and kinedyn's
# Python qdd at each); pinocchio_loops.cpp (built header-only with -O3 -march=native, cached in
# $KINEDYN_BENCH_DIR, default /tmp/kinedyn-cpp-bench) and the Rust bench `loops` (target-cpu=native)
# read the same file. The three sides' qdd must agree to 1e-9 (relative above 1) at every state
# before any time is printed. KINEDYN_BENCH_ROUNDS (default 5) alternations, each side keeping its
# fastest run. Per call: the states taken in turn; per state of a batch: kinedyn's one call over
# 1024 states on one thread (SIMD lanes), against Pinocchio's per call (it has no batch).
set -euo pipefail
cd "$(dirname "$0")/../.."
SP=$(python -c "import site; print(site.getsitepackages()[0])")
INC="$SP/cmeel.prefix/include"
OUT=${KINEDYN_BENCH_DIR:-/tmp/kinedyn-cpp-bench}
mkdir -p "$OUT"
BIN="$OUT/pinocchio_loops"
if [ ! -x "$BIN" ] || [ benches/cpp/pinocchio_loops.cpp -nt "$BIN" ] || [ benches/cpp/harness.hpp -nt "$BIN" ]; then
  echo "compiling Pinocchio's constrained dynamics (several minutes)..." >&2
  g++ -O3 -march=native -DNDEBUG -std=c++17 -w -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 \
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -I"$INC" -I"$INC/eigen3" \
    benches/cpp/pinocchio_loops.cpp -o "$BIN.new"
  mv "$BIN.new" "$BIN"
fi
RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$OUT/target" cargo bench -q -p kinedyn-core --bench loops --no-run 2>/dev/null
RUST=$(ls -t "$OUT"/target/release/deps/loops-* | grep -v '\.d$' | head -1)
PYTHONPATH=${PYTHONPATH:-python} python benches/cpp/dump_loops.py "$OUT/loops" "$@" > "$OUT/loops.txt"
mapfile -t FILES < "$OUT/loops.txt"
export KINEDYN_BENCH_LOOPS=$(IFS=:; echo "${FILES[*]}")
: > "$OUT/loops_cpp.txt"; : > "$OUT/loops_rust.txt"
for round in $(seq "${KINEDYN_BENCH_ROUNDS:-5}"); do
  "$BIN" "${FILES[@]}" >> "$OUT/loops_cpp.txt"
  "$RUST" --bench >> "$OUT/loops_rust.txt"
done
echo "load average at the end: $(cut -d' ' -f1-3 /proc/loadavg)"
python - "$OUT/loops_cpp.txt" "$OUT/loops_rust.txt" "${FILES[@]}" <<'PY'
import sys
def read(path):
    best, checks, other = {}, {}, {}
    for line in open(path):
        key, *values = line.split()
        if "/check_" in key:
            checks.setdefault(key, []).append([float(x) for x in values])
        elif key.endswith("_differs"):
            other[key] = values[0]
        else:
            best[key] = min(best.get(key, float("inf")), float(values[0]))
    return best, checks, other
(cpp, cpp_checks, cpp_other), (rust, rust_checks, _) = read(sys.argv[1]), read(sys.argv[2])
names = []
for path in sys.argv[3:]:
    lines = open(path).read().splitlines()
    name = lines[0].split()[1]
    nq, nv, _ = (int(x) for x in lines[1].split()[1:])
    rows = sum(3 if l.split()[1] == "point" else 6 for l in lines if l.startswith("loop "))
    states = [[float(x) for x in l.split()[1:]] for l in lines if l.startswith("state ")]
    expect = [x for s in states for x in s[nq + 2 * nv:]]
    key = f"{name}/check_qdd"
    sides = [("Pinocchio C++", cpp_checks.get(key)), ("kinedyn-core", rust_checks.get(key)), ("kinedyn Python", [expect])]
    for side, values in sides:
        if values is None:
            sys.exit(f"CHECK FAILED: {side} printed no {key} line")
    reference = sides[0][1][0]
    worst_of = {}
    for side, rounds in sides:
        for values in rounds:
            if len(values) != len(reference):
                sys.exit(f"CHECK FAILED: {key}: {side} has {len(values)} numbers, Pinocchio C++ {len(reference)}")
            worst = max(abs(x - y) / max(1.0, abs(y)) for x, y in zip(values, reference))
            worst_of[side] = max(worst_of.get(side, 0.0), worst)
            if worst > 1e-9:
                sys.exit(f"CHECK FAILED: {key}: {side} differs from Pinocchio C++ by {worst:.3g} (> 1e-9)")
    print(f"{name}: nq {nq}, nv {nv}, {rows} loop rows, {len(states)} closed states: qdd agree "
          f"(largest difference from Pinocchio: kinedyn-core {worst_of['kinedyn-core']:.1e}, Python {worst_of['kinedyn Python']:.1e})")
    names.append(name)
print(f"\n{'ns':14s} {'constraintDynamics':>18s} {'lcaba':>8s} {'kinedyn':>8s} {'ratio':>6s} | per state of 1024: "
      f"{'off':>6s} {'avx2':>6s} {'avx512':>6s} {'ratio':>6s}")
for name in names:
    cd, kd = cpp[f"{name}/constraintDynamics"], rust[f"{name}/cfd"]
    lc = cpp.get(f"{name}/lcaba")
    lc_text = f"{lc:8.0f}" if lc else f"{'differs ' + cpp_other.get(name + '/lcaba_differs', '?'):>8s}"
    lanes = [rust.get(f"{name}/cfd_batch_{kind}") for kind in ("off", "avx2", "avx512")]
    best = min(x for x in lanes if x)
    lane_text = " ".join(f"{x:6.0f}" if x else f"{'-':>6s}" for x in lanes)
    print(f"{name:14s} {cd:18.0f} {lc_text} {kd:8.0f} {cd / kd:6.2f} | {'':18s} {lane_text} {cd / best:6.2f}")
print("ratio: constraintDynamics ns / kinedyn ns (above 1: kinedyn faster); the batch's against "
      "constraintDynamics per call, its best lane kind")
PY
