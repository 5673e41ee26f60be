"""The package as users get it: ``pip install`` from the source tree into a fresh virtual
environment (no index, no CMake build), ``import splinegrid`` from a source checkout, stubs that
match the .proto files, and a clean ``mypy -p splinegrid``."""

import os
import pathlib
import shutil
import subprocess
import sys
import time

import pytest
from google.protobuf import descriptor_pb2

import splinegrid
from splinegrid import _stubs
from splinegrid.v1 import archive_pb2, grid_pb2
from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

from conftest import REPO

PYTHON = REPO / "python"
INSTALL_SECONDS = 30  # the whole install must stay quick (measured: about 5 s)


def run(command, **kwargs):
    result = subprocess.run([str(c) for c in command], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, check=False, **kwargs)
    assert result.returncode == 0, f"{' '.join(map(str, command))}:\n{result.stdout}"
    return result.stdout


def test_pip_install_from_source_without_a_build(tmp_path):
    """The README's command, in a copy of the tree (pip builds in place and leaves build/)."""
    tree = tmp_path / "src"
    shutil.copytree(PYTHON, tree / "python",
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    shutil.copytree(REPO / "proto" / "splinegrid", tree / "proto" / "splinegrid")
    venv = tmp_path / "venv"
    start = time.monotonic()
    run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", venv])
    run([venv / "bin" / "pip", "install", "--no-build-isolation", "--no-index",
         tree / "python"], env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"})
    seconds = time.monotonic() - start
    assert seconds < INSTALL_SECONDS
    shutil.rmtree(tree)  # the installed package must not need the source any more
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # only the venv's copy
    out = run([venv / "bin" / "python", "-c", (
        "import pathlib, splinegrid, splinegrid.v1.splinegrid_service_pb2_grpc as g\n"
        "root = pathlib.Path(splinegrid.__file__).parent\n"
        "print(root.parent.name, sorted(p.name for p in (root / 'v1').iterdir()"
        " if p.suffix in ('.py', '.pyi')), (root / 'py.typed').is_file(),"
        " hasattr(g, 'SplineGridStub'))")], cwd=tmp_path, env=clean)
    assert out.split()[0] == "site-packages"
    assert "'grid_pb2.pyi'" in out and "'splinegrid_service_pb2_grpc.py'" in out
    assert out.strip().endswith("True True")


def test_import_from_the_source_tree(tmp_path):
    """PYTHONPATH=python: the stubs are generated into the cache on first import."""
    env = dict(os.environ, PYTHONPATH=str(PYTHON), XDG_CACHE_HOME=str(tmp_path / "cache"))
    code = ("import splinegrid, splinegrid.v1.grid_pb2 as g\n"
            "print(splinegrid.__file__); print(g.__file__)")
    first = run([sys.executable, "-c", code], env=env, cwd=tmp_path).split()
    assert first[0] == str(PYTHON / "splinegrid" / "__init__.py")
    key = _stubs.digest(str(REPO / "proto"))
    assert first[1] == str(tmp_path / "cache" / "splinegrid-stubs" / key / "splinegrid" / "v1"
                           / "grid_pb2.py")
    assert run([sys.executable, "-c", code], env=env, cwd=tmp_path).split() == first


def test_source_tree_without_protos_says_what_to_do(tmp_path):
    shutil.copytree(PYTHON / "splinegrid", tmp_path / "python" / "splinegrid",
                    ignore=shutil.ignore_patterns("__pycache__", "*_pb2*"))
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "python"))
    result = subprocess.run([sys.executable, "-c", "import splinegrid"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert result.returncode != 0
    assert "pip install ./python" in result.stdout


def test_stubs_match_the_protos(tmp_path):
    """The imported stubs (whichever way they were made) describe the current .proto files:
    a stale BUILD/python after a proto change fails here."""
    descriptors = tmp_path / "protos.pb"
    run(["protoc", f"-I{REPO / 'proto'}", f"--descriptor_set_out={descriptors}",
         *_stubs.PROTOS], cwd=REPO / "proto")
    files = descriptor_pb2.FileDescriptorSet.FromString(descriptors.read_bytes()).file
    for file in files:  # the Python generator leaves out the (derived) JSON names
        _clear_json_names(file.message_type)
    expected = {f.name: f for f in files}
    for module in (grid_pb2, archive_pb2, service_pb2):
        name = module.DESCRIPTOR.name
        got = descriptor_pb2.FileDescriptorProto.FromString(module.DESCRIPTOR.serialized_pb)
        assert got == expected[name], f"{name}: the stubs at {module.__file__} are stale"


def _clear_json_names(messages):
    for message in messages:
        for field in message.field:
            field.ClearField("json_name")
        _clear_json_names(message.nested_type)


def test_mypy_is_clean(tmp_path):
    """``mypy -p splinegrid`` with the package's configuration (python/pyproject.toml) over
    the package and its generated stubs with their .pyi files."""
    shutil.copytree(pathlib.Path(splinegrid.__file__).parent, tmp_path / "splinegrid",
                    ignore=shutil.ignore_patterns("__pycache__", "*_pb2*"))
    _stubs.generate(str(REPO / "proto"), str(tmp_path))
    out = run(["/usr/bin/python3", "-m", "mypy", "--config-file", PYTHON / "pyproject.toml",
               "--cache-dir", tmp_path / ".mypy_cache", "-p", "splinegrid"], cwd=tmp_path)
    assert out.startswith("Success: no issues found")


def test_missing_compiler_is_named(tmp_path, monkeypatch):
    monkeypatch.setenv("SPLINEGRID_PROTOC", str(tmp_path / "no-protoc"))
    with pytest.raises(_stubs.StubError, match="SPLINEGRID_PROTOC"):
        _stubs.generate(str(REPO / "proto"), str(tmp_path / "out"))
    monkeypatch.delenv("SPLINEGRID_PROTOC")
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(_stubs.StubError, match="protobuf-compiler"):
        _stubs.generate(str(REPO / "proto"), str(tmp_path / "out"))
