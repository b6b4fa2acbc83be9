"""The table of compare_codegen.sh (issue 30): reads the outputs its rounds left in OUT_DIR, checks that
the sides computed the same numbers, counts the generated code's operations and prints ns per call,
ratios and the arithmetic floor.

    python benches/cpp/codegen_table.py OUT_DIR TREE_FILE...
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

ALGORITHMS = ("rnea", "crba", "mass_matrix_inverse", "aba", "rnea_derivatives", "aba_derivatives")
SHORT = {"mass_matrix_inverse": "M^-1", "rnea_derivatives": "dRNEA", "aba_derivatives": "dABA"}


def read(path: Path):
    """(fastest ns per key, check numbers per key and round, other lines) of one side's output."""
    best, checks, other = {}, {}, {}
    if not path.exists():
        return best, checks, other
    for line in path.read_text().splitlines():
        if not line.strip():
            continue
        key, *values = line.split()
        if "/check_" in key:
            checks.setdefault(key, []).append([float(x) for x in values])
        elif len(values) == 1 and re.fullmatch(r"[-+.\deE]+", values[0]):
            best[key] = min(best.get(key, float("inf")), float(values[0]))
        else:
            other[key] = values
    return best, checks, other


def agree(key: str, sides: list[tuple[str, list[list[float]]]]) -> None:
    """Every round of every side equal to the first side's first round (1e-9, relative above 1)."""
    reference = sides[0][1][0]
    for side, rounds in sides:
        for values in rounds:
            if len(values) != len(reference):
                sys.exit(f"CHECK FAILED: {key}: {side} has {len(values)} numbers, {sides[0][0]} {len(reference)}")
            worst = max((abs(x - y) / max(1.0, abs(y)) for x, y in zip(values, reference)), default=0.0)
            if worst > 1e-9:
                sys.exit(f"CHECK FAILED: {key}: {side} differs from {sides[0][0]} by {worst:.3g} (> 1e-9)")


# one C assignment's arithmetic: binary + - * / between operands (array elements, numbers, names,
# closing brackets); a unary minus or a sign in a number's exponent is no operation
BINARY = re.compile(r"(?<=[\w\])])\s*([-+*/])\s*(?=[\w(.\[-])")


def generated_ops(sources: Path) -> tuple[int, int]:
    """(+ - * / operations, calls of sin/cos) in the forward-zero function(s) of one generated library."""
    ops = calls = 0
    for path in sorted(sources.glob("*.c")):
        if "forward_zero" not in path.name or "sparsity" in path.name:
            continue
        for line in path.read_text().splitlines():
            line = line.strip()
            if "=" not in line or line.startswith(("//", "/*", "*", "#")) or not line.endswith(";"):
                continue
            rhs = line.split("=", 1)[1]
            rhs = re.sub(r"\d[\d.]*[eE][-+]?\d+", "1", rhs)  # 1.5e-07: one number
            ops += len(BINARY.findall(rhs))
            calls += len(re.findall(r"\b(?:sin|cos)\(", rhs))
    return ops, calls


def peak_ops_per_ns() -> float:
    if "KINEDYN_PEAK_OPS_PER_NS" in os.environ:
        return float(os.environ["KINEDYN_PEAK_OPS_PER_NS"])
    for line in open("/proc/cpuinfo"):
        if line.startswith("cpu MHz"):
            return 4 * float(line.split(":")[1]) / 1000  # 4 scalar double operations per cycle
    return 4 * 2.6


def main() -> None:
    out, trees = Path(sys.argv[1]), sys.argv[2:]
    cpp, cpp_checks, cpp_other = read(out / "codegen_cpp.txt")
    rust, rust_checks, _ = read(out / "codegen_rust.txt")
    special, special_checks, _ = read(out / "codegen_special.txt")
    flops = {
        line.split()[0]: line.split()[1:]
        for line in (out / "codegen_flops.txt").read_text().splitlines()
        if line.strip()
    }
    names = []
    for tree in trees:
        lines = dict(line.split(maxsplit=1) for line in open(tree) if line.startswith(("robot", "expect_rnea")))
        name = lines["robot"].strip()
        names.append(name)
        expect = [[float(x) for x in lines["expect_rnea"].split()]]
        for alg in ALGORITHMS:
            key = f"{name}/check_{alg}"
            sides = [("Pinocchio C++ (generic)", cpp_checks.get(key)), ("kinedyn-core", rust_checks.get(key))]
            if alg == "rnea":
                sides.append(("kinedyn Python", expect))
            if special:
                sides.append(("kinedyn specialised", special_checks.get(key)))
            for side, values in sides:
                if values is None and not (side == "kinedyn specialised" and f"{name}/{alg}" not in special):
                    sys.exit(f"CHECK FAILED: {side} printed no {key} line")
            agree(key, [(s, v) for s, v in sides if v is not None])
        print(f"{name}: the generic results agree (1e-9) on {', '.join(ALGORITHMS)}; the generated code checked in C++")
    peak = peak_ops_per_ns()
    print(
        f"\nns per call; ratio = codegen / kinedyn (above 1: kinedyn faster); floor = operations / "
        f"{peak:.1f} per ns (the scalar peak); reach = floor / time"
    )
    header = f"{'':26s} {'codegen':>8s} {'kinedyn':>8s} {'ratio':>6s}"
    if special:
        header += f" {'special':>8s} {'ratio':>6s}"
    header += (
        f" | {'cg ops':>7s} {'floor':>6s} {'reach':>5s} | {'kd ops':>7s} {'floor':>6s} {'reach':>5s}"
        f" {'recorded':>8s} | {'sin/cos':>7s}"
    )
    print(header)
    builds = []
    for name in names:
        record_s = compile_s = 0.0
        for alg in ALGORITHMS:
            key = f"{name}/{alg}"
            c, k = cpp.get(key + "_codegen"), rust.get(key)
            build = cpp_other.get(key + "_codegen_build")
            cg_ops, cg_trig = generated_ops(Path(build[2])) if build and len(build) > 2 else (0, 0)
            if build:
                record_s, compile_s = record_s + float(build[0]), compile_s + float(build[1])
            kd_ops, kd_trig = (int(x) for x in flops.get(key + "_flops", ["0", "0"]))
            recorded = flops.get(key + "_recorded_ops", ["-"])[0]
            row = f"{name + ' ' + SHORT.get(alg, alg.upper()):26s} {c:8.0f} {k:8.0f} {c / k:6.2f}"
            if special:
                s = special.get(key)
                row += f" {s:8.0f} {c / s:6.2f}" if s else f" {'-':>8s} {'-':>6s}"
            cg_floor, kd_floor = cg_ops / peak, kd_ops / peak
            row += (
                f" | {cg_ops:7d} {cg_floor:6.0f} {cg_floor / c:5.0%} | {kd_ops:7d} {kd_floor:6.0f}"
                f" {kd_floor / k:5.0%} {recorded:>8s} | {cg_trig:3d}/{kd_trig:<3d}"
            )
            print(row)
        builds.append(f"{name} {record_s:.1f} s recording + {compile_s:.1f} s generating and compiling")
    print("\nCppADCodeGen, the six algorithms per robot (when their libraries were built): " + "; ".join(builds))


if __name__ == "__main__":
    main()
