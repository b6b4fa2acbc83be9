"""Write the HTML report of a robot (default: the tutorial arm) into the current folder; open it in
a browser. Same as `kinedyn report [ROBOT]`.

Run: python examples/05_report.py [ROBOT]
"""

import sys

import kinedyn as kd
from kinedyn.report import write_report

name = sys.argv[1] if len(sys.argv) > 1 else "planar_2r"
path = write_report(kd.robots.get(name), f"{name}.html", name=name, t_end=1.0)
print(f"wrote {path} ({path.stat().st_size // 1024} KiB)")
assert "<math" in path.read_text()
