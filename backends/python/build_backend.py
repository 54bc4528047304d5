"""PEP 517 build backend of `pip install .`: configures the project with CMake for the running
interpreter, builds the module target alone and packs it into a wheel. Standard library only."""
import base64
import hashlib
import os
import pathlib
import re
import subprocess
import sys
import sysconfig
import tempfile
import tomllib
import zipfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _project():
    with open(ROOT / "pyproject.toml", "rb") as f:
        project = tomllib.load(f)["project"]
    cmake_version = re.search(r"project\(bundletrack VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text()).group(1)
    if project["version"] != cmake_version:
        raise RuntimeError(f"pyproject.toml says version {project['version']}, CMakeLists.txt {cmake_version}")
    return project


def _tag():
    interpreter = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{interpreter}-{interpreter}-{platform}"


def _metadata(project):
    lines = ["Metadata-Version: 2.1", f"Name: {project['name']}", f"Version: {project['version']}",
             f"Summary: {project['description']}", f"Requires-Python: {project['requires-python']}"]
    lines += [f"Requires-Dist: {d}" for d in project.get("dependencies", [])]
    return "\n".join(lines) + "\n"


def _build_module(build_dir):
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
    subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                    f"-DPython_EXECUTABLE={sys.executable}", "-DBUNDLETRACK_PYTHON=ON", "-DBUNDLETRACK_BUILD_TESTS=OFF",
                    "-DBUNDLETRACK_BUILD_EXAMPLES=OFF", "-DBUNDLETRACK_BUILD_BENCH=OFF"], check=True, stdout=sys.stderr)
    subprocess.run(["cmake", "--build", str(build_dir), "--target", "bundletrack_python", "-j", jobs], check=True,
                   stdout=sys.stderr)
    (module,) = (build_dir / "python").glob("bundletrack*" + sysconfig.get_config_var("EXT_SUFFIX"))
    return module


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    project = _project()
    dist_info = f"{project['name']}-{project['version']}.dist-info"
    wheel_name = f"{project['name']}-{project['version']}-{_tag()}.whl"
    with tempfile.TemporaryDirectory() as build_dir:
        module = _build_module(pathlib.Path(build_dir))
        files = {module.name: module.read_bytes(),
                 f"{dist_info}/METADATA": _metadata(project).encode(),
                 f"{dist_info}/WHEEL": f"Wheel-Version: 1.0\nGenerator: bundletrack build_backend\n"
                                       f"Root-Is-Purelib: false\nTag: {_tag()}\n".encode()}
        record = [_record_line(name, data) for name, data in files.items()] + [f"{dist_info}/RECORD,,"]
        files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()
        with zipfile.ZipFile(pathlib.Path(wheel_directory) / wheel_name, "w", zipfile.ZIP_DEFLATED) as wheel:
            for name, data in files.items():
                wheel.writestr(name, data)
    return wheel_name
