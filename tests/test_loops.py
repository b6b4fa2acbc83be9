"""Closed loops as a robot declares them (kinedyn.description.loops, Robot.add_loop)."""

import pickle

import pytest

import kinedyn as kd


@pytest.fixture
def arm():
    return kd.robots.planar_2r()


def test_add_loop_returns_a_new_robot_and_keeps_the_tree(arm):
    closed = arm.add_loop("tool", "base", kind="point")
    assert arm.loops == ()
    assert [(lp.name, lp.frame_a, lp.frame_b, lp.kind, lp.rows) for lp in closed.loops] == [
        ("loop0", "tool", "base", "point", 3)
    ]
    assert closed.add_loop("link1", "base", kind="weld").loops[1].rows == 6
    assert closed.nq == arm.nq and closed.frame_names == arm.frame_names


def test_loops_survive_edits_and_pickling(arm):
    closed = arm.add_loop("tool", "base", name="pin")
    for other in (closed.lock_joints([0]), pickle.loads(pickle.dumps(closed)), closed.replace(name="x")):
        assert other.loops == closed.loops


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("tool", "nowhere"), "unknown frame 'nowhere'"),
        (("tool", "tool"), "on itself"),
        (("tool", "base", "pin"), "kind must be one of"),
    ],
)
def test_bad_loops_are_named(arm, args, message):
    with pytest.raises(ValueError, match=message):
        arm.add_loop(*args)


def test_two_loops_with_one_name_are_refused(arm):
    with pytest.raises(ValueError, match="two loops are named 'a'"):
        arm.add_loop("tool", "base", name="a").add_loop("link1", "base", name="a")
