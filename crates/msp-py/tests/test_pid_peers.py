"""The PID as simple-pid's users expect it: simple-pid's own tests
(m-lundberg/simple-pid, tests/test_pid.py) ported where msp's Pid expresses
the same feature, in its parallel form ``Pid.parallel(kp, ki, kd, ts)`` with
the derivative on the measurement (``c = 0``, unfiltered). Where msp's
convention differs it is stated and msp's is tested: the integral is forward
Euler (the error of a sample enters the next output, so a pure I controller
starts at 0), and the return to automatic is bumpless (it continues from the
last output instead of clearing the integral)."""

import math

import pytest

from msp import Pid


def p_only(kp: float) -> Pid:
    return Pid.parallel(kp, 0.0, 0.0, 1.0)


def test_zero() -> None:
    assert Pid.parallel(1, 1, 1, 1.0).update(0, 0) == 0


def test_p() -> None:
    pid = p_only(1)
    assert pid.update(10, 0) == 10
    assert pid.update(10, 5) == 5
    assert pid.update(10, -5) == 15


def test_p_negative_setpoint() -> None:
    pid = p_only(1)
    assert [pid.update(-10, y) for y in (0, 5, -5, -15)] == [-10, -15, -5, 5]


def test_i() -> None:
    # simple-pid: ki = 10, dt = 0.1, e = 10 gives 10, then 20 (the integral
    # includes the present error); msp's forward Euler gives 0, 10, 20
    pid = Pid.parallel(0.0, 10.0, 0.0, 0.1)
    assert [round(pid.update(10, 0), 9) for _ in range(3)] == [0, 10, 20]
    pid = Pid.parallel(0.0, 10.0, 0.0, 0.1)
    assert [round(pid.update(-10, 0), 9) for _ in range(3)] == [0, -10, -20]


def test_d() -> None:
    # derivative on the measurement (c = 0), unfiltered (tf = 0): no kick on
    # the first sample, 0 for a constant input, −kd·Δy/dt after
    pid = Pid.parallel(0.0, 0.0, 0.1, 0.1, tf=0.0, c=0.0)
    assert pid.update(10, 0) == 0
    assert pid.update(10, 0) == 0
    assert pid.update(10, 0) == 0
    assert round(pid.update(10, 5), 9) == -5
    assert round(pid.update(10, 15), 9) == -10


def test_desired_state() -> None:
    assert Pid.parallel(10, 5, 2, 1.0).update(10, 10) == 0


def test_output_limits() -> None:
    pid = Pid.parallel(100, 20, 40, 0.1, umin=0, umax=100)
    assert 0 <= pid.update(10, 0) <= 100
    assert 0 <= pid.update(10, -100) <= 100


def test_starting_output() -> None:
    # simple-pid's starting_output: msp's preset
    pid = p_only(1)
    pid.preset(25)
    assert pid.update(10, 10) == 25


def test_auto_mode() -> None:
    pid = p_only(1)
    assert pid.update(10, 0) == 10
    assert pid.update(10, 5) == 5
    pid.set_manual()  # the output held, as simple-pid's auto_mode = False
    assert pid.update(10, 1) == 5
    assert pid.update(10, 7) == 5
    # simple-pid clears the integral on the return; msp is bumpless: a
    # manual output given and then auto continues from it (set_auto_mode's
    # last_output)
    pid = Pid.parallel(1.0, 0.5, 0.0, 1.0)
    pid.set_manual()
    pid.set_manual_output(25)
    pid.set_auto()
    assert pid.update(3, 3) == 25


def test_separate_components() -> None:
    pid = Pid.parallel(1, 0, 1, 0.1, tf=0.0, c=0.0)
    assert pid.update(10, 0) == 10
    assert (pid.p, pid.i, pid.d) == (10, 0, 0)
    assert round(pid.update(10, 5)) == -45
    assert (round(pid.p), round(pid.i), round(pid.d)) == (5, 0, -50)


def test_repr_names_the_settings_and_builds_the_controller() -> None:
    text = repr(Pid(2.0, ti=10.0, td=0.5, ts=0.1, umin=0, umax=1))
    for part in ("kp=2", "ti=10", "td=0.5", "ts=0.1", "umin=0", "umax=1"):
        assert part in text, text
    # eval(repr(p)) computes p's outputs: the ISA form, the parallel form (a
    # pure I controller, which the ISA form cannot hold), every setting
    import msp
    for pid in (Pid(2.0, ti=10.0, td=0.5, ts=0.1, umin=0, umax=1),
                Pid.parallel(1, 2, 3, 0.01),
                Pid.parallel(0, 10, 0, 0.1),
                Pid(0.5, ti=4.0, ts=0.1, n=8.0, b=0.5, c=0.0, anti_windup="clamping", rate_limit=2.0),
                Pid(1.0, ts=0.2, anti_windup="none")):
        twin = eval(repr(pid), {"msp": msp})
        assert repr(twin) == repr(pid)
        for k in range(50):
            r, y = (1.0 if k > 2 else 0.0), 0.01 * k
            assert twin.update(r, y) == pid.update(r, y), repr(pid)


def test_a_pure_integral_controller_keeps_its_gain() -> None:
    pid = Pid.parallel(0, 10, 0, 0.1)
    assert pid.params == {"kp": 0.0, "ti": None, "td": None, "ki": 10.0, "kd": 0.0}
    assert "nan" not in repr(pid).lower()
    # forward Euler: 0 first, then ki·ts·e = 1
    assert pid.update(1.0, 0.0) == 0.0 and math.isclose(pid.update(1.0, 0.0), 1.0)


def test_converge_system() -> None:
    # simple-pid's integrating process pv' = c − 1 at dt = 0.01, limits ±5
    pid = Pid.parallel(1, 0.8, 0.04, 0.01, umin=-5, umax=5)
    pv = 0.0
    for _ in range(12000):
        pv += (pid.update(5, pv) - 1) * 0.01
    assert abs(pv - 5) < 0.1


def test_given_values_are_not_dropped() -> None:
    # kp = 0 in the ISA form would silently drop ti and td
    with pytest.raises(ValueError, match="parallel"):
        Pid(0.0, ti=0.1, td=0.1)
    with pytest.raises(ValueError, match="anti_windup"):
        Pid(1.0, anti_windup="x")
    assert Pid(1.0, ti=2.0, anti_windup="clamping").update(1, 0) == 1


def test_finite_inputs_never_latch() -> None:
    pid = Pid(2.0, ti=1.0, td=0.1, ts=0.1, umin=-10, umax=10)
    pid.update(0, 0.5)
    assert math.isfinite(pid.update(0, 1.7e308))
    assert pid.fault
    outs = [pid.update(1, 0.5) for _ in range(20)]
    assert all(math.isfinite(u) for u in outs) and not pid.fault


def test_both_forms_read_the_same_options_and_refuse_an_unknown_one_by_name() -> None:
    """``Pid`` and ``Pid.parallel`` take the :class:`msp.PidOptions` keywords, read in one
    place: the same limits clamp both forms alike; a misspelt keyword or a value of the wrong
    type is a TypeError that names it."""
    import typing

    from msp import PidOptions

    assert set(typing.get_type_hints(PidOptions)) == {
        "b", "c", "umin", "umax", "anti_windup", "tt", "rate_limit"}
    isa = Pid(2.0, ti=10.0, ts=1.0, umin=-0.5, umax=0.5, b=0.5)
    par = Pid.parallel(2.0, 0.2, 0.0, 1.0, umin=-0.5, umax=0.5, b=0.5)
    assert [isa.update(1.0, 0.0) for _ in range(3)] == [par.update(1.0, 0.0) for _ in range(3)]
    assert isa.update(1.0, 0.0) == 0.5
    for make in (lambda: Pid(1.0, umax_=1.0), lambda: Pid.parallel(1.0, umax_=1.0)):
        with pytest.raises(TypeError, match="'umax_'"):
            make()
    with pytest.raises(TypeError, match="'umin'"):
        Pid(1.0, umin="low")
    with pytest.raises(ValueError, match="anti_windup 'windup'"):
        Pid(1.0, ti=5.0, anti_windup="windup")
    assert Pid(1.0, ti=5.0, tt=None).params["kp"] == 1.0
