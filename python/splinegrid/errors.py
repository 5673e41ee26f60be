"""The exception of failed calls, and the translation of gRPC's errors into it."""

from __future__ import annotations

import contextlib
from typing import Iterator, Optional

import grpc


class SplinegridError(grpc.RpcError):  # type: ignore[misc]  # grpc is untyped
    """A failed call: ``code`` is the gRPC status code name, ``message`` the server's message."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code
        self.message = message

    @property
    def status_code(self) -> Optional[grpc.StatusCode]:
        """``code`` as a ``grpc.StatusCode`` (None if gRPC has no such code)."""
        return grpc.StatusCode.__members__.get(self.code)

    @classmethod
    def from_rpc_error(cls, error: grpc.RpcError) -> SplinegridError:
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        return cls(code.name, details or "")


def _code(error: grpc.RpcError) -> grpc.StatusCode:
    return error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN


def _broke_off(error: grpc.RpcError) -> bool:
    """Whether a call ended because it broke off rather than being answered: UNAVAILABLE (the
    server went away or is stopping, a balancer had no upstream), or INTERNAL "RST_STREAM" (a
    balancer reset a half-sent stream when its upstream died: nginx does, and gRPC reports it
    as INTERNAL "Received RST_STREAM with error code 2"). The C++ client's ``BrokeOff``."""
    code = _code(error)
    if code == grpc.StatusCode.UNAVAILABLE:
        return True
    details = error.details() if hasattr(error, "details") else ""
    return code == grpc.StatusCode.INTERNAL and "RST_STREAM" in (details or "")


@contextlib.contextmanager
def _translated_errors() -> Iterator[None]:
    """grpc.RpcError -> SplinegridError (chained)."""
    try:
        yield
    except SplinegridError:
        raise
    except grpc.RpcError as error:
        raise SplinegridError.from_rpc_error(error) from error


def _data_loss(message: str) -> SplinegridError:
    return SplinegridError("DATA_LOSS", message)
