"""Wall-clock event lines that the simulated nodes append to one file per run."""
from __future__ import annotations

import json
import os
import threading
import time
from typing import Any, List, Optional


class EventLog:
    def __init__(self, path: Optional[str]) -> None:
        self.path = path
        self._lock = threading.Lock()
        self._once: set = set()

    def log(self, event: str, once: bool = False, **fields: Any) -> None:
        """Append {"event", "wall", …}; with once=True only the first of that event."""
        if not self.path:
            return
        with self._lock:
            if once:
                if event in self._once:
                    return
                self._once.add(event)
            line = json.dumps({"event": event, "wall": time.time(), **fields}) + "\n"
            fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
            try:
                os.write(fd, line.encode())
            finally:
                os.close(fd)


def read_events(path: str) -> List[dict]:
    if not os.path.exists(path):
        return []
    with open(path) as fh:
        return [json.loads(line) for line in fh if line.strip()]
