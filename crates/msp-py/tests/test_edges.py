"""Python at the edges: what would have taken the interpreter down (a
constructor's delay line beyond memory), values that were dropped without a
word, and the autotuner's errors. Each runs in a subprocess where an abort
would be possible, so that an abort fails the test instead of the suite."""

import math
import subprocess
import sys

import pytest

import msp


def _survives(code: str) -> str:
    """Runs ``code`` in a fresh interpreter; its stdout. An abort or a kill fails."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, f"exit {out.returncode}: {out.stderr[-2000:]}"
    return out.stdout


@pytest.mark.parametrize(
    "call",
    [
        'msp.SmithPredictor("5.6*e^-93.9s/(40.2s+1)", ts=1e-13)',
        'msp.KaranDey("0.2/s*e^-7.4s", ts=1e-9)',
        'msp.SmithPredictor("2*e^-3s/(4s+1)", ts=0.1, max_dead_time=1e9)',
        'msp.SmithPredictor("e^-4e8s/(s+1)", ts=0.1)',
        'msp.FilteredSmithUnstable("e^-4e8s/(5s-1)", ts=0.1)',
    ],
)
def test_constructors_check_memory_first(call: str) -> None:
    out = _survives(
        "import msp\n"
        "try:\n"
        f"    {call}\n"
        "    print('built')\n"
        "except ValueError as e:\n"
        "    print('refused:', e)\n"
    )
    assert out.startswith("refused:") and "the limit is" in out, out


@pytest.mark.parametrize("bad", [float("nan"), -1.0, float("inf")])
def test_max_dead_time_must_be_a_length(bad: float) -> None:
    with pytest.raises(ValueError, match="max_dead_time"):
        msp.SmithPredictor("2*e^-3s/(4s+1)", ts=0.1, max_dead_time=bad)


def test_run_with_a_huge_budget_fails_cleanly() -> None:
    out = _survives(
        "import msp\n"
        "try:\n"
        "    msp.run('2*e^-3s/(4s+1)', 'smith', events=['20:dead-time=1e9'], max_memory=2**63)\n"
        "    print('ran')\n"
        "except ValueError as e:\n"
        "    print('refused:', e)\n"
    )
    assert out.startswith("refused:"), out


@pytest.mark.parametrize("actuator", [(0, 1, 2), (0,)])
def test_actuator_is_a_pair(actuator: tuple) -> None:
    with pytest.raises(ValueError, match="two values"):
        msp.run("1/(s+1)", actuator=actuator)


def test_autotune_errors_are_value_errors() -> None:
    # a model that cannot fit the relay data of an integrating plant
    with pytest.raises(ValueError, match="does not fit"):
        msp.autotune("0.7*e^-2s/(s*(4s+1))", model="sopdt")
    # a reverse-acting plant is autotuned, not refused
    res = msp.autotune("-1.5*e^-4s/(10s+1)")
    assert res["identified"]["k"] < 0 and res["run"].stable is True


@pytest.mark.parametrize("make", [
    lambda: msp.AstromHangLim("0.2/s*e^-7.4s", ts=0.1),
    lambda: msp.KaranDey("0.2/s*e^-7.4s", ts=0.1),
    lambda: msp.FilteredSmithUnstable("e^-2s/(5s-1)", ts=0.1),
    lambda: msp.SmithPredictor("2*e^-3s/(4s+1)", ts=0.1),
])
@pytest.mark.parametrize("spike", [1e308, -1e308, 1e100])
def test_a_measurement_too_large_to_compute_with_is_a_fault_that_clears(make, spike: float) -> None:
    """Beyond 2**256 (f64) a finite measurement is a fault exactly as NaN is: the output held,
    the fault raised for that sample only, and the next samples those of a twin that saw NaN
    (no state took the value; the spike of 1e100 would have overflowed a predictor)."""
    c, twin = make(), make()
    for _ in range(50):
        assert c.update(1.0, 0.0) == twin.update(1.0, 0.0)
    held = c.update(1.0, spike)
    assert math.isfinite(held) and c.fault
    assert twin.update(1.0, float("nan")) == held
    for _ in range(50):
        u = c.update(1.0, 0.0)
        assert math.isfinite(u) and not c.fault and u == twin.update(1.0, 0.0)
