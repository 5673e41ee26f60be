"""Build steps of the splinegrid package beyond pyproject.toml's metadata.

- ``build_py`` generates the ``splinegrid.v1`` stubs (and their ``.pyi`` type stubs) from the
  .proto files into the build tree, so every wheel holds stubs that match the protos it was
  built from (``splinegrid/_stubs.py``: compilers, and why nothing generated is checked in).
- ``sdist`` copies those .proto files into the archive (``proto/splinegrid/v1``), since a
  source distribution of ``python/`` would not otherwise contain ``../proto``.
"""

import importlib.util
import os
import shutil

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

HERE = os.path.dirname(os.path.abspath(__file__))


def _stubs():
    """splinegrid/_stubs.py, loaded by path: the package itself is not importable yet."""
    spec = importlib.util.spec_from_file_location(
        "_splinegrid_stubs", os.path.join(HERE, "splinegrid", "_stubs.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _proto_root(stubs):
    root = stubs.find_proto_root(os.path.join(HERE, "splinegrid"))
    if root is None:
        raise SystemExit("splinegrid: proto/splinegrid/v1/*.proto not found beside python/ "
                         "(source checkout) or in python/proto (sdist)")
    return root


class BuildPyWithStubs(build_py):
    """build_py, then protoc into the build directory."""

    def run(self):
        super().run()
        stubs = _stubs()
        try:
            written = stubs.generate(_proto_root(stubs), self.build_lib)
        except stubs.StubError as error:
            raise SystemExit(f"splinegrid: {error}") from None
        for path in written:
            self.announce(f"generated {path}", level=2)


class SdistWithProtos(sdist):
    """sdist, with the .proto files the stubs are generated from."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        stubs = _stubs()
        root = _proto_root(stubs)
        for proto in stubs.PROTOS:
            target = os.path.join(base_dir, "proto", proto)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            shutil.copyfile(os.path.join(root, proto), target)


setup(cmdclass={"build_py": BuildPyWithStubs, "sdist": SdistWithProtos})
