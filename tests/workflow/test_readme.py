"""Every command of the README's code blocks is run by a test (issue: a researcher's first
hour): the Snakemake commands as dry runs that must plan their targets, the command line
in a temporary folder, and the test command as the line CI runs. A command added to the
README that no rule here knows fails the test."""

import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from mcfbench.cli import main

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
INSTALL = "pip install -c constraints.txt -e "


def commands():
    """The command lines of the README's ```bash blocks, in order."""
    lines, inside = [], False
    for line in README.splitlines():
        if line.startswith("```"):
            inside = line.strip() == "```bash" if not inside else False
            continue
        if inside and line.strip():
            lines.append(line.strip())
    return lines


def test_the_readme_has_the_two_quick_start_commands_and_ci_runs_the_second():
    found = commands()
    assert found[:2] == [f'{INSTALL}. && snakemake --cores 2',
                         f'{INSTALL}".[test]" && python -m pytest -n 2']
    assert found[1] in (ROOT / ".ci" / "run").read_text().splitlines()


def _snakemake_dry_run(command):
    args = shlex.split(command.split("&&")[-1])
    assert args[0] == "snakemake"
    return subprocess.run([sys.executable, "-m", *args, "-n"], cwd=ROOT, capture_output=True,
                          text=True, timeout=600)


@pytest.mark.e2e
@pytest.mark.parametrize("command", [c for c in commands() if "snakemake" in c])
def test_every_snakemake_command_of_the_readme_plans_its_targets(command):
    out = _snakemake_dry_run(command)
    assert out.returncode == 0, out.stdout[-2000:] + out.stderr[-2000:]
    text = out.stdout + out.stderr
    assert "Traceback" not in text
    if "select" in command:                 # the one-minute matrix: only what it names
        planned = {line.split()[0].split("_")[1] for line in text.splitlines()
                   if line.startswith("runs_")}
        assert planned and planned <= {"sphere", "real"}, planned     # real_nut


@pytest.mark.e2e
@pytest.mark.parametrize("command", [c for c in commands() if c.startswith("python -m mcfbench")])
def test_every_command_line_of_the_readme_runs(command, tmp_path, monkeypatch, capsys):
    args = shlex.split(command)[3:]
    args = [str(ROOT / a) if a.startswith("mcfbench/data/") else
            str(tmp_path / Path(a).name) if a.startswith("results/") else a for a in args]
    monkeypatch.chdir(tmp_path)
    assert main(args) == 0
    for a in args:
        if a.startswith(str(tmp_path)):
            assert Path(a).stat().st_size > 0, a


def test_no_readme_command_is_left_without_a_test():
    for command in commands():
        assert (command.startswith(INSTALL) or command.startswith("snakemake ")
                or command.startswith("python -m mcfbench ")), command
