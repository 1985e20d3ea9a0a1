"""What the Python tests share: the repository, the CLI binary and its CSV,
and the comparison of a Python result with the CLI's."""

from __future__ import annotations

import csv
import io
import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

import msp

ROOT = pathlib.Path(__file__).resolve().parents[3]

MSP_BIN = os.environ.get("MSP_BIN", str(ROOT / "target" / "debug" / "msp"))


def cli_csv(*args: str) -> dict[str, np.ndarray]:
    out = subprocess.run([MSP_BIN, "run", "-q", *args], check=True, capture_output=True, text=True).stdout
    rows = list(csv.reader(io.StringIO(out)))
    header, data = rows[0], rows[1:]
    return {h: np.array([float(r[i]) for r in data]) for i, h in enumerate(header)}


def _same(py: object, cli: object, where: str = "") -> None:
    """``py`` equals the JSON value ``cli``: NaN where the JSON has null, floats bit for bit."""
    if isinstance(cli, dict):
        assert isinstance(py, dict) and set(py) == set(cli), (where, py, cli)
        for k in cli:
            _same(py[k], cli[k], f"{where}.{k}")
    elif isinstance(cli, list):
        assert isinstance(py, list) and len(py) == len(cli), where
        for i, (a, b) in enumerate(zip(py, cli)):
            _same(a, b, f"{where}[{i}]")
    elif cli is None and isinstance(py, float):
        assert math.isnan(py), where
    else:
        assert py == cli, (where, py, cli)
