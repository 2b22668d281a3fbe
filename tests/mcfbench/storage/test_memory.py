"""The glibc malloc tuning (mcfbench/storage/memory.py): an explicit call, with an opt-out."""

import subprocess
import sys

CODE = "from mcfbench.storage.memory import tune_malloc; print(tune_malloc())"


def _run(env_value=None):
    import os

    env = dict(os.environ)
    env.pop("DDFV_MALLOC_TUNING", None)
    if env_value is not None:
        env["DDFV_MALLOC_TUNING"] = env_value
    return subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True,
                          env=env, check=True).stdout.strip()


def test_tuning_is_applied_on_glibc_and_can_be_switched_off():
    import platform

    assert _run() == str(platform.libc_ver()[0] == "glibc")
    assert _run("0") == "False"


def test_available_memory_is_read_from_meminfo(tmp_path, monkeypatch):
    from mcfbench.storage import memory

    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       24000000 kB\nMemFree:         1000 kB\n"
                       "MemAvailable:    2097152 kB\n")
    monkeypatch.setattr(memory, "MEMINFO", meminfo)
    assert memory.available_mb() == 2048.0
    monkeypatch.setattr(memory, "MEMINFO", tmp_path / "absent")
    assert memory.available_mb() is None


def test_resident_memory_grows_with_an_allocation():
    import numpy as np

    from mcfbench.storage.memory import peak_rss_mb, resident_mb

    before = resident_mb()
    block = np.ones(2**25 // 8 * 4)                   # 128 MB, touched
    assert 100 < resident_mb() - before < 160 and peak_rss_mb() > before + 100
    del block
