"""Progress bars: on a terminal the level sweep of ``study`` shows one, into a pipe or a
log nothing (mcfbench.cli, mcfbench.running.run.level_sweep, mcfbench.running.driver)."""

import fcntl
import os
import pty
import re
import struct
import subprocess
import sys
import termios

from mcfbench.running.driver import simulate
from mcfbench.running.schemes import get_scheme

STUDY = [sys.executable, "-m", "mcfbench", "study", "sphere", "--levels", "1", "2",
         "--scheme", "cotan"]


def _env():
    return {**os.environ, "COLUMNS": "100"}


def test_no_progress_bar_when_stderr_is_not_a_terminal():
    ran = subprocess.run(STUDY, capture_output=True, text=True, env=_env(), timeout=120,
                         check=False)
    assert ran.returncode == 0, ran.stderr
    assert ran.stderr == ""                       # no bar, no carriage return
    assert "\r" not in ran.stdout and "level" in ran.stdout and "162" in ran.stdout


def test_progress_bar_of_the_levels_on_a_terminal():
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))  # 24 x 100
    proc = subprocess.Popen(STUDY, stdin=subprocess.DEVNULL, stdout=slave, stderr=slave,
                            env=_env())
    os.close(slave)
    chunks = []
    while True:
        try:
            chunk = os.read(master, 4096)
        except OSError:                           # EIO: the child closed the terminal
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(master)
    assert proc.wait(timeout=120) == 0
    screen = b"".join(chunks).decode(errors="replace")
    assert "sphere:" in screen and "1/2" in screen and "level 2" in screen
    assert "\r" in screen                         # redrawn in place
    # wiped when done (blanks over the bar's line), the table from the line's start
    assert re.search(r"level 2\]\r {50,}\rcotangent on shrinking sphere", screen), screen


def test_simulate_writes_no_bar_without_progress(capsys):
    from mcfbench.geometry.spheres import icosphere

    V, F = icosphere(1)
    traj = simulate(get_scheme("cotan").make(V, F, 1e-3), 3, progress=False)
    assert traj.steps_done == 3
    captured = capsys.readouterr()
    assert captured.err == "" and captured.out == ""


def test_simulate_bar_closes_with_the_run(capsys, monkeypatch):
    """With ``progress`` and no delay the bar is drawn on stderr and wiped at the end."""
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running import driver

    monkeypatch.setattr(driver, "PROGRESS_DELAY", 0.0)
    V, F = icosphere(1)
    traj = simulate(get_scheme("cotan").make(V, F, 1e-3), 4, progress=True)
    assert traj.steps_done == 4
    err = capsys.readouterr().err
    assert "0/4 [00:00<?, ?step/s]" in err
    assert err.endswith("\r") and err.split("\r")[-2].strip() == ""   # wiped (leave=False)
