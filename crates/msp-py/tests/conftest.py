"""Test-suite policy: under the project's test command (``MSP_NO_SKIP=1``) a
skipped test is a failure, so that a missing binary or package never hides a
comparison."""

from __future__ import annotations

import os

import pytest


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):  # type: ignore[no-untyped-def]
    outcome = yield
    report = outcome.get_result()
    if os.environ.get("MSP_NO_SKIP") == "1" and report.skipped:
        report.outcome = "failed"
        report.longrepr = f"skipped under MSP_NO_SKIP=1: {report.longrepr}"
