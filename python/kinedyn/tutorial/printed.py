"""The seed tutorial's questions and its printed answers (METR4202 Tutorial 4), as data.

``PRINTED`` is the one place that holds the tutorial's printed answers (transcribed as printed, so
misprints included); ``QUESTION_DATA`` holds the questions' inputs. Conventions: docs/seed-notes.md.
"""

from __future__ import annotations

from typing import Any

import sympy as sp

QUESTIONS = ["1a", "1b", "2a", "2b", "3", "challenge"]

# ------------------------------------------------------------------ the tutorial's inputs
QUESTION_DATA: dict[str, dict[str, Any]] = {
    "2a": {"l1": 2.0, "l2": 3.0, "theta_deg": (167.028, -156.44), "theta_decimals": (3, 2), "qd": (1.0, 3.0)},
    "2b": {"F": (30.0, -20.0)},
    "challenge": {"L1": 3.0, "L2": 2.0, "L3": 1.0, "tool": (1.0, 0.2, 0.5)},
}

# ------------------------------------------------------------------ printed in the tutorial
# The answers as printed in the tutorial's solutions (misprints kept). Symbolic answers are SymPy
# strings in th1, th2 (joint angles), thd1, thd2 (rates), thdd1, thdd2, l1, l2, m1, m2, g; numbers are
# strings so that the printed number of digits is kept. Never used as a source of truth: each is
# compared with kinedyn and with an independent check.
PRINTED: dict[str, dict[str, Any]] = {
    "1a": {
        "J": "Matrix([[-l1*sin(th1) - l2*sin(th1 + th2), -l2*sin(th1 + th2)],"
        " [l1*cos(th1) + l2*cos(th1 + th2), l2*cos(th1 + th2)]])"
    },
    "1b": {
        "J_inv": "Matrix([[l2*cos(th1 + th2), l2*sin(th1 + th2)],"
        " [-l1*cos(th1) - l2*cos(th1 + th2), -l1*sin(th1) - l2*sin(th1 + th2)]])/(l1*l2*sin(th2))"
    },
    "2a": {"J": [["-1.0000", "-0.5512"], ["1.0000", "2.9489"]], "v": ["-2.654", "9.847"]},
    "2b": {"tau": ["-50.0", "-75.1"]},
    "3": {
        "v_D^2": "thd1**2*(l1**2 + l2**2/4 + l1*l2*cos(th2)) + thd2**2*(l2**2/4) + thd1*thd2*(l2**2/2 + l1*l2*cos(th2))",
        "K": "thd1**2*(m1*l1**2/6 + m2*l2**2/6 + m2*l1**2/2 + m2*l1*l2*cos(th2)/2) + thd2**2*(m2*l2**2/6)"
        " + thd1*thd2*(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)",
        "P": "m1*g*l1/2*sin(th1) + m2*g*(l1*sin(th1) + l2/2*sin(th1 + th2))",
        # printed with "theta-dot squared" (no index) in the first term; read as thd1**2
        "L": "thd1**2*(m1*l1**2/6 + m2*l2**2/6 + m2*l1**2/2 + m2*l1*l2*cos(th2)/2) + thd2**2*(m2*l2**2/6)"
        " + thd1*thd2*(m2*l2**2/3 + m2*l1*l2*cos(th2)/2) - m1*g*l1/2*sin(th1) - m2*g*(l1*sin(th1) + l2/2*sin(th1 + th2))",
        "d/dt dL/dthd1": "(m1*l1**2/3 + m2*l1**2 + m2*l2**2/3 + m2*l1*l2*cos(th2))*thdd1 + (m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd2"
        " - m2*l1*l2*sin(th2)*thd1*thd2 - m2*l1*l2*sin(th2)*thd2**2/2",
        "dL/dth1": "(m1/2 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th1 + th2)/2",
        "tau1": "(m1*l1**2/3 + m2*l1**2 + m2*l2**2/3 + m2*l1*l2*cos(th2))*thdd1 + (m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd2"
        " - m2*l1*l2*sin(th2)*thd1*thd2 - m2*l1*l2*sin(th2)*thd2**2/2 + (m1/2 + m2)*g*l1*cos(th1) + m2*g*l2*cos(th1 + th2)/2",
        "d/dt dL/dthd2": "(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd1 + m2*l2**2/3*thdd2 - m2*l1*l2*sin(th2)*thd1**2/2"
        " - m2*l1*l2*sin(th2)*thd1*thd2",
        "dL/dth2": "m2*l1*l2*sin(th2)*thd1*thd2 + m2*g*l2*cos(th1 + th2)/2",
        "tau2": "(m2*l2**2/3 + m2*l1*l2*cos(th2)/2)*thdd1 + m2*l2**2/3*thdd2 - m2*l1*l2*sin(th2)*thd1**2/2 + m2*g*l2*cos(th1 + th2)/2",
    },
    # the challenge question comes with no printed solution
}

# the tutorial's symbols
th1, th2, thd1, thd2, thdd1, thdd2 = sp.symbols("th1 th2 thd1 thd2 thdd1 thdd2", real=True)
l1, l2, m1, m2, g = sp.symbols("l1 l2 m1 m2 g", positive=True)
_PRINTED_NS = {
    "th1": th1,
    "th2": th2,
    "thd1": thd1,
    "thd2": thd2,
    "thdd1": thdd1,
    "thdd2": thdd2,
    "l1": l1,
    "l2": l2,
    "m1": m1,
    "m2": m2,
    "g": g,
    "Matrix": sp.Matrix,
    "sin": sp.sin,
    "cos": sp.cos,
}


def printed(question: str, key: str):
    """A symbolic printed answer as a SymPy expression in the tutorial's symbols."""
    return sp.sympify(PRINTED[question][key], locals=_PRINTED_NS)
