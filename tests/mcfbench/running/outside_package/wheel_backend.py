"""A PEP 517 build backend of the standard library alone: builds the wheel of the
``[project]`` table (name, version, dependencies, entry points; the pure Python
packages listed in ``[tool.wheel_backend] packages``), so that pip builds and
installs the package offline with nothing else installed (setuptools 65 needs the
``wheel`` package, which the lock does not have)."""

import base64
import hashlib
import tomllib
import zipfile
from pathlib import Path


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    config = tomllib.loads(Path("pyproject.toml").read_text())
    project = config["project"]
    name, version = project["name"].replace("-", "_"), project["version"]
    info = f"{name}-{version}.dist-info"
    requires = "".join(f"Requires-Dist: {r}\n" for r in project.get("dependencies", ()))
    files = {f"{info}/METADATA": f"Metadata-Version: 2.1\nName: {project['name']}\n"
                                 f"Version: {version}\n{requires}",
             f"{info}/WHEEL": "Wheel-Version: 1.0\nGenerator: wheel_backend\n"
                              "Root-Is-Purelib: true\nTag: py3-none-any\n",
             f"{info}/entry_points.txt": "".join(
                 f"[{group}]\n" + "".join(f"{k} = {v}\n" for k, v in points.items())
                 for group, points in project.get("entry-points", {}).items())}
    for package in config["tool"]["wheel_backend"]["packages"]:
        for path in sorted(Path(package).rglob("*.py")):
            files[path.as_posix()] = path.read_text()
    wheel = f"{name}-{version}-py3-none-any.whl"
    record = [_record_line(k, v.encode()) for k, v in files.items()] + [f"{info}/RECORD,,"]
    with zipfile.ZipFile(Path(wheel_directory) / wheel, "w") as archive:
        for k, v in {**files, f"{info}/RECORD": "\n".join(record) + "\n"}.items():
            archive.writestr(k, v)
    return wheel
