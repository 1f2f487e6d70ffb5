# `pip install .` (pyproject.toml, setup.py): a copy of the package's files installed by pip into a
# fresh virtual environment (with the system's site-packages, where Debian's numpy and setuptools
# are), reusing the build directory ctest runs from (BUCKLE_BUILD_DIR: its module is up to date,
# so nothing is compiled), then imported from another directory and run.
import json
import os
import pathlib
import re
import shutil
import subprocess
import sys

import pytest

import buckle


def needs(module, package):
    if subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True).returncode != 0:
        pytest.skip(f"{module} cannot be imported by {sys.executable} (Debian: {package}): pip install . not tested")


def test_pip_install_from_the_checkout_into_a_venv(source_dir, tmp_path):
    needs("pip", "python3-pip")
    needs("setuptools", "python3-setuptools")
    needs("wheel", "python3-wheel")
    needs("venv", "python3-venv")
    build = os.environ.get("BUCKLE_BUILD_DIR")
    if not build:
        pytest.fail("BUCKLE_BUILD_DIR must name the CMake build directory (ctest sets it)")
    # the files pip's build reads, copied: nothing is written into the checkout
    src = tmp_path / "src"
    for name in ("setup.py", "pyproject.toml", "CMakeLists.txt", "docs/python.md"):
        (src / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source_dir / name, src / name)
    shutil.copytree(source_dir / "python" / "buckle", src / "python" / "buckle")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", "--system-site-packages", str(venv)], check=True)
    python = str(venv / "bin" / "python")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # not the build tree's module
    env["BUCKLE_BUILD_DIR"] = build
    done = subprocess.run([python, "-m", "pip", "install", "-v", "--no-build-isolation", "--no-index", "--no-deps", str(src)],
                          capture_output=True, text=True, env=env, timeout=600, cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    log = done.stdout + done.stderr
    assert "Built target buckle_python" in log  # CMake's target was brought up to date ...
    assert "Building CXX object" not in log  # ... by compiling nothing: the existing build reused
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    scene = source_dir / "data" / "scenes" / "fig2.json"
    check = f"""
import importlib.metadata, json, sys
import buckle
r = buckle.run_scene({str(scene)!r})
meta = importlib.metadata.metadata("buckle")
print(json.dumps({{"file": buckle.__file__, "version": buckle.__version__, "meta_version": meta["Version"],
                  "requires": meta.get_all("Requires-Dist"), "extras": meta.get_all("Provides-Extra"),
                  "files": sorted(str(f) for f in importlib.metadata.files("buckle")),
                  "specials": [(p["type"], p["parameter"]) for p in r["special_points"]],
                  "result": type(r).__name__, "label": r.label("Fx")}}))
"""
    run = subprocess.run([python, "-c", check], capture_output=True, text=True, env=env, timeout=120, cwd=elsewhere)
    assert run.returncode == 0, run.stderr
    got = json.loads(run.stdout)
    assert pathlib.Path(got["file"]).resolve().is_relative_to(venv.resolve())
    version = re.search(r"project\(buckle VERSION ([0-9.]+)", (source_dir / "CMakeLists.txt").read_text())[1]
    assert got["version"] == got["meta_version"] == version == buckle.__version__
    assert sorted(r.replace(" ", "") for r in got["requires"]) == [
        "matplotlib;extra=='plots'", "numpy", "pandas;extra=='frames'"]
    assert sorted(got["extras"]) == ["frames", "plots"]
    installed = [f for f in got["files"] if f.startswith("buckle/")]
    for name in ("__init__.py", "_result.py", "_plot.py"):
        assert "buckle/" + name in installed
    assert any(re.fullmatch(r"buckle/_core\..*\.so", f) for f in installed)
    # the installed package computes what the build tree's does
    here = buckle.run_scene(scene)
    assert got["specials"] == [[p["type"], p["parameter"]] for p in here["special_points"]]
    assert got["result"] == "RunResult" and got["label"] == here.label("Fx")
