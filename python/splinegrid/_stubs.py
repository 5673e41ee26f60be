"""Generation of the ``splinegrid.v1`` stubs from the service's .proto files (standard library
only, so that ``setup.py`` can load this file before the package is importable).

The stubs are generated, never checked in: the .proto files in ``proto/splinegrid/v1`` are the
one definition, and they grow (additive changes) while the package stays the same. Three places
generate them, all with the same compilers:

- ``pip install ./python`` (``setup.py``'s ``build_py``) into the wheel, with ``.pyi`` type
  stubs for mypy;
- the CMake target ``splinegrid_python`` into ``BUILD/python``;
- ``import splinegrid`` from a source checkout without either (``splinegrid/v1/__init__.py``),
  into a cache directory keyed by the .proto files' contents.

The compilers are Debian's ``protoc`` (``protobuf-compiler``, 3.21: proto3 ``optional`` and
``--pyi_out``) and ``grpc_python_plugin`` (``protobuf-compiler-grpc``), both installed by
``.ci/setup``. Debian's ``python3-grpc-tools`` is not used: it bundles protoc 3.6, which rejects
the ``optional`` fields of archive.proto. ``SPLINEGRID_PROTOC`` and
``SPLINEGRID_GRPC_PYTHON_PLUGIN`` name other executables.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from typing import Optional, Sequence

# The service's .proto files, relative to the proto root (imports are "splinegrid/v1/...").
PROTOS = ("splinegrid/v1/grid.proto", "splinegrid/v1/archive.proto",
          "splinegrid/v1/splinegrid_service.proto")
SERVICE_PROTO = "splinegrid/v1/splinegrid_service.proto"  # the only one with a service

# The generated modules, relative to the output root.
MODULES = ("splinegrid/v1/grid_pb2.py", "splinegrid/v1/archive_pb2.py",
           "splinegrid/v1/splinegrid_service_pb2.py",
           "splinegrid/v1/splinegrid_service_pb2_grpc.py")


class StubError(RuntimeError):
    """The stubs cannot be generated (no compiler, a missing .proto file, protoc failed)."""


def find_proto_root(package_dir: str) -> Optional[str]:
    """The directory holding ``splinegrid/v1/*.proto`` for the package at ``package_dir``
    (``.../python/splinegrid``): ``python/proto`` in an sdist, else ``proto`` of the source
    checkout (``python/../proto``); None when neither has them."""
    python_dir = os.path.dirname(os.path.abspath(package_dir))
    for root in (os.path.join(python_dir, "proto"),
                 os.path.join(os.path.dirname(python_dir), "proto")):
        if all(os.path.isfile(os.path.join(root, p)) for p in PROTOS):
            return root
    return None


def digest(proto_root: str) -> str:
    """A short hash of the .proto files' contents (names the cache directory)."""
    h = hashlib.sha256()
    for proto in PROTOS:
        with open(os.path.join(proto_root, proto), "rb") as file:
            h.update(proto.encode() + b"\0" + file.read() + b"\0")
    return h.hexdigest()[:16]


def _tool(variable: str, name: str, package: str) -> str:
    given = os.environ.get(variable)
    path = shutil.which(given or name)
    if given and not path:
        raise StubError(f"{variable} = {given!r} is not an executable")
    if not path:
        raise StubError(f"{name} not found (Debian package {package}, installed by .ci/setup; "
                        f"or set {variable}): it generates the splinegrid.v1 stubs")
    return path


def generate(proto_root: str, out_root: str, pyi: bool = True) -> list[str]:
    """Generates the stubs of the .proto files under ``proto_root`` into
    ``out_root/splinegrid/v1/`` (with ``.pyi`` type stubs when ``pyi``); returns the files
    written, relative to ``out_root``. Raises :class:`StubError` naming what is missing."""
    missing = [p for p in PROTOS if not os.path.isfile(os.path.join(proto_root, p))]
    if missing:
        raise StubError(f"{', '.join(missing)} not found under {proto_root}")
    protoc = _tool("SPLINEGRID_PROTOC", "protoc", "protobuf-compiler")
    plugin = _tool("SPLINEGRID_GRPC_PYTHON_PLUGIN", "grpc_python_plugin",
                   "protobuf-compiler-grpc")
    out_root = os.path.abspath(out_root)
    os.makedirs(os.path.join(out_root, "splinegrid", "v1"), exist_ok=True)
    outputs = [f"--python_out={out_root}"] + ([f"--pyi_out={out_root}"] if pyi else [])
    _run([protoc, f"-I{proto_root}", *outputs, *PROTOS], cwd=proto_root)
    # The gRPC plugin only for the service's file (the others would get empty *_pb2_grpc.py).
    _run([protoc, f"-I{proto_root}", f"--grpc_out={out_root}",
          f"--plugin=protoc-gen-grpc={plugin}", SERVICE_PROTO], cwd=proto_root)
    written = list(MODULES)
    if pyi:
        written += [m[:-3] + ".pyi" for m in MODULES if not m.endswith("_grpc.py")]
    return written


def cached(proto_root: str) -> str:
    """The directory ``.../splinegrid/v1`` of stubs generated from ``proto_root`` in the user's
    cache (``$XDG_CACHE_HOME`` or ``~/.cache``, else the temporary directory), generating them
    on first use. The directory is named by :func:`digest`, so an edited .proto file gets new
    stubs; it is written under a temporary name and renamed into place, so concurrent first
    imports do not see half a directory."""
    key = digest(proto_root)
    bases = [os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
             os.path.join(tempfile.gettempdir(), f"splinegrid-{os.getuid()}")]
    errors = []
    for base in bases:
        final = os.path.join(base, "splinegrid-stubs", key)
        stubs = os.path.join(final, "splinegrid", "v1")
        if all(os.path.isfile(os.path.join(final, m)) for m in MODULES):
            return stubs
        try:
            os.makedirs(os.path.dirname(final), exist_ok=True)
            work = tempfile.mkdtemp(prefix=f"{key}.", dir=os.path.dirname(final))
            try:
                generate(proto_root, work, pyi=False)
                os.rename(work, final)
            except OSError:
                shutil.rmtree(work, ignore_errors=True)
                if not os.path.isdir(stubs):  # not another process's rename that won
                    raise
            return stubs
        except OSError as error:
            errors.append(f"{final}: {error.strerror or error}")
    raise StubError("cannot write the generated stubs: " + "; ".join(errors))


def _run(command: Sequence[str], cwd: Optional[str] = None) -> None:
    result = subprocess.run(command, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, check=False)
    if result.returncode != 0:
        raise StubError(f"{' '.join(command)} failed ({result.returncode}): "
                        f"{result.stderr.strip()}")


def main(argv: Sequence[str]) -> int:
    """``python3 _stubs.py PROTO_ROOT OUT_ROOT``: generate (used by hand and by tests)."""
    if len(argv) != 2:
        print("usage: _stubs.py PROTO_ROOT OUT_ROOT", file=sys.stderr)
        return 2
    try:
        for path in generate(argv[0], argv[1]):
            print(path)
    except StubError as error:
        print(error, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
