#!/usr/bin/python3
"""A gRPC proxy in front of a splinegrid server that loses answers, for the e2e tests of the
coupling clients: DeformGrid calls are forwarded and then answered UNAVAILABLE (the revision was
stored, the client does not know) or refused UNAVAILABLE before forwarding; EvaluateGrid calls
are refused or broken off after their first message. Faults follow each method's call count, so
a run is reproducible.

    fault_proxy.py UPSTREAM PORT_FILE     (writes its port to PORT_FILE once it listens)
"""

import os
import sys
import threading
from concurrent import futures

import grpc

from splinegrid.v1 import splinegrid_service_pb2 as service_pb2

SERVICE = "splinegrid.v1.SplineGrid"


def fault(method: str, n: int):
    """The fault of the n-th call of ``method`` (1-based): "lost", "refused", "torn" or None."""
    if method == "DeformGrid":
        return "lost" if n % 3 == 0 else "refused" if n % 5 == 1 and n > 1 else None
    if method == "EvaluateGrid":
        return "refused" if n % 4 == 0 else "torn" if n % 7 == 0 else None
    return None


class Proxy(grpc.GenericRpcHandler):
    def __init__(self, channel: grpc.Channel) -> None:
        self._channel = channel
        self._kinds = {m.name: (m.client_streaming, m.server_streaming)
                       for m in service_pb2.DESCRIPTOR.services_by_name["SplineGrid"].methods}
        self._counts: dict[str, int] = {}
        self._lock = threading.Lock()

    def _fault(self, method: str):
        with self._lock:
            n = self._counts[method] = self._counts.get(method, 0) + 1
        return fault(method, n)

    def service(self, details):
        path = details.method
        method = path.rsplit("/", 1)[-1]
        if not path.startswith(f"/{SERVICE}/") or method not in self._kinds:
            return None
        metadata = list(details.invocation_metadata)
        same = lambda data: data  # noqa: E731 (bytes pass through)
        client_streaming, server_streaming = self._kinds[method]
        if client_streaming and server_streaming:
            return None
        if client_streaming:
            upstream = self._channel.stream_unary(path, same, same)

            def upload(requests, context):
                try:
                    return upstream(requests, metadata=metadata)
                except grpc.RpcError as error:
                    context.abort(error.code(), error.details())
            return grpc.stream_unary_rpc_method_handler(upload, same, same)
        if server_streaming:
            upstream = self._channel.unary_stream(path, same, same)

            def stream(request, context):
                kind = self._fault(method)
                if kind == "refused":
                    context.abort(grpc.StatusCode.UNAVAILABLE, "injected: no upstream")
                try:
                    for i, message in enumerate(upstream(request, metadata=metadata)):
                        if kind == "torn" and i == 1:
                            context.abort(grpc.StatusCode.UNAVAILABLE, "injected: torn stream")
                        yield message
                except grpc.RpcError as error:
                    context.abort(error.code(), error.details())
            return grpc.unary_stream_rpc_method_handler(stream, same, same)
        upstream = self._channel.unary_unary(path, same, same)

        def unary(request, context):
            kind = self._fault(method)
            if kind == "refused":
                context.abort(grpc.StatusCode.UNAVAILABLE, "injected: no upstream")
            try:
                response = upstream(request, metadata=metadata,
                                    timeout=context.time_remaining())
            except grpc.RpcError as error:
                context.abort(error.code(), error.details())
            if kind == "lost":
                context.abort(grpc.StatusCode.UNAVAILABLE, "injected: the answer was lost")
            return response
        return grpc.unary_unary_rpc_method_handler(unary, same, same)


def main() -> None:
    upstream, port_file = sys.argv[1], sys.argv[2]
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=8),
                         handlers=[Proxy(grpc.insecure_channel(upstream))])
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    with open(port_file + ".tmp", "w") as file:
        file.write(str(port))
    os.replace(port_file + ".tmp", port_file)
    server.wait_for_termination()


if __name__ == "__main__":
    main()
