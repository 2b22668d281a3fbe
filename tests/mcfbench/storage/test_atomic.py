"""Atomic output (mcfbench/storage/atomic.py): a kill at any moment leaves the old file or the new one."""

import signal
import subprocess
import sys
import time
import zipfile

import numpy as np
import pytest

from mcfbench.storage.atomic import check_writable, save_npz, write_json, write_text

WRITER = """
import sys
import numpy as np
from mcfbench.storage.atomic import save_npz
data = np.random.default_rng(int(sys.argv[2])).random((500_000,))   # 4 MB
save_npz(sys.argv[1], data=data, tag=np.array(int(sys.argv[2])))
print("ready", flush=True)
while True:
    save_npz(sys.argv[1], data=data, tag=np.array(int(sys.argv[2])))
"""


def _valid(path):
    """The file loads completely as the archive the writer writes."""
    with np.load(path) as archive:
        return archive["data"].shape == (500_000,) and archive["tag"].ndim == 0


def test_kill_during_npz_write_never_leaves_an_invalid_file(tmp_path):
    target = tmp_path / "run.npz"
    rng = np.random.default_rng(1)
    for attempt in range(6):
        proc = subprocess.Popen([sys.executable, "-c", WRITER, str(target), str(attempt)],
                                stdout=subprocess.PIPE, text=True)
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(rng.uniform(0.0, 0.6))         # somewhere inside a later write
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        try:
            assert _valid(target)
        except (zipfile.BadZipFile, EOFError, ValueError, OSError) as err:
            pytest.fail(f"attempt {attempt}: {target} is damaged: {err}")


def test_npz_is_written_under_exactly_the_given_name(tmp_path):
    save_npz(tmp_path / "result.dat", x=np.arange(3))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.dat"]
    with np.load(tmp_path / "result.dat") as data:
        assert data["x"].tolist() == [0, 1, 2]


def test_failed_write_keeps_the_old_file(tmp_path):
    path = tmp_path / "table.json"
    write_json(path, {"a": 1.5, "b": float("nan")})
    assert path.read_text() == '{\n  "a": 1.5,\n  "b": null\n}\n'
    with pytest.raises(TypeError):
        write_json(path, {"a": object()})
    assert path.read_text() == '{\n  "a": 1.5,\n  "b": null\n}\n'
    assert [p.name for p in tmp_path.iterdir()] == ["table.json"]
    assert oct(path.stat().st_mode & 0o777) == oct(0o644)


def test_unwritable_outputs_are_refused_before_any_work(tmp_path):
    blocker = tmp_path / "file"
    write_text(blocker, "x")
    with pytest.raises(ValueError, match="is a file, not a directory"):
        check_writable(blocker / "sub" / "out.npz")
    with pytest.raises(ValueError, match="is a directory"):
        check_writable(tmp_path)
    check_writable(tmp_path / "new" / "deeper" / "out.npz")      # missing folders are fine
