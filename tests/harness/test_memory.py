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
