"""A test file as plain data: its tests, their inputs and expectations, each with its line."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from .messages import Path
from .yamlpos import TestFileError

UNSET: Any = object()  # a node-sample value the sample leaves out


@dataclass
class MessageInput:
    """One message (or part of one: same topic and instant merge) at a time."""

    time: float
    topic: str
    assignments: List[Tuple[Path, Any]]
    line: int


@dataclass
class TopicInput:
    topic: str
    type_name: str
    cls: Any
    line: int


@dataclass
class NodeSampleInput:
    node: str
    time: float
    alive: Any
    cpu: Any
    memory: Any
    line: int


@dataclass
class Expect:
    kind: str  # start, release, never, active
    name: Any  # a behaviour's name or number, or an action
    line: int
    at: float = 0.0
    start: float = 0.0  # active: from
    end: float = 0.0  # active: to
    tolerance: Optional[float] = None


@dataclass
class Case:
    name: str
    line: int
    covers: List[str]
    duration: Optional[float]
    tolerance: float
    topics: Dict[str, TopicInput] = field(default_factory=dict)
    messages: List[MessageInput] = field(default_factory=list)
    nodes: List[NodeSampleInput] = field(default_factory=list)
    expects: List[Expect] = field(default_factory=list)
    covers_lines: List[int] = field(default_factory=list)  # the line of each `covers` value
    readable: bool = True  # False: an error in its inputs or expectations (reported): it cannot run

    @property
    def end(self) -> float:
        """The test's duration: as given, else the last input or expected instant + 2 s."""
        if self.duration is not None:
            return self.duration
        times = [m.time for m in self.messages] + [n.time for n in self.nodes]
        times += [max(e.at, e.end) for e in self.expects]
        return max(times, default=0.0) + 2.0


@dataclass
class TestFile:
    path: str
    spec: str
    spec_line: int
    actions: List[str]
    cases: List[Case]
    model: Any = None  # the system model (rubass.lang.sysmodel.SystemModel) named by `model:`, if any
    errors: List[TestFileError] = field(default_factory=list)  # every error found, in the file's order
