"""XML-RPC proxies with a timeout: a hung master or node must not stall the thread asking it."""
from __future__ import annotations

import xmlrpc.client
from typing import Any


class _TimeoutTransport(xmlrpc.client.Transport):
    def __init__(self, timeout: float) -> None:
        super().__init__()
        self.timeout = timeout

    def make_connection(self, host: Any) -> Any:
        conn = super().make_connection(host)
        conn.timeout = self.timeout
        return conn


def proxy(uri: str, timeout: float) -> xmlrpc.client.ServerProxy:
    """A proxy whose every call gives up (socket.timeout) after `timeout` seconds."""
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))
