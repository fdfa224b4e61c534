"""Shared fixtures of the Python module's tests: the command-line tool (OMNIVERT_CLI, set by
CTest) and small simulated datasets rendered by it."""
import os
import pathlib
import subprocess

import pytest

CLI = os.environ.get("OMNIVERT_CLI", "omnivert")
REAL_DATA = pathlib.Path(os.environ.get("OMNIVERT_REAL_DATA_DIR", "/nonexistent"))


def cli(*args, expect=0):
    """Runs the tool; asserts its exit code; returns the finished process (text output)."""
    p = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == expect, f"{args}: exit {p.returncode}\n{p.stdout}\n{p.stderr}"
    return p


def simulate(out, *args):
    cli("simulate", "--out", out, "--force", *args)
    return out


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """12 frames of the paper's experiment in the corridor (straight driving)."""
    return simulate(tmp_path_factory.mktemp("short") / "run", "--world", "corridor",
                    "--trajectory", "paper", "--seed", "3", "--frames", "12")


@pytest.fixture(scope="module")
def demo_run(tmp_path_factory):
    """The demo's run (scripts/demo): the paper's experiment in the corridor, seed 1."""
    return simulate(tmp_path_factory.mktemp("demo") / "paper", "--world", "corridor",
                    "--trajectory", "paper", "--seed", "1")


def first_frame(run):
    """Path of a dataset's first image."""
    line = (run / "cam0" / "data.csv").read_text().splitlines()[1]
    return run / "cam0" / "data" / line.split(",")[1].strip()
