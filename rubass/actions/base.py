"""What an action plugin is: configured from its library entry, set up before the first tick,
then driven through start / hold / release by its own runner thread."""
from __future__ import annotations

import importlib
import inspect
import linecache
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from ..lang.errors import Diagnostic
from ..lang.library import ActionDef
from ..lang.stdlib import is_standard_library


# Python keeps a module it imported: a reload (SIGHUP, ~reload) reads the library again, not the code
_CODE_CACHED = " (its module is loaded already: after changing the plugin's code, restart the monitor)"


class ActionSetupError(Exception):
    """An action that cannot work as configured (unknown type, bad message fields, …)."""


@dataclass(frozen=True)
class Context:
    """Why a phase runs: the behaviour, its line, the rules that made it true, the call's arguments."""

    behaviour: int
    line: int
    rules: Tuple[str, ...] = ()
    args: Tuple[Any, ...] = ()
    time: float = 0.0
    key: Any = None  # the behaviour's identity across reloads (its signature); None: use `behaviour`

    @property
    def ident(self) -> Any:
        """Who holds the action: the behaviour and the call's arguments, so that two calls of one
        action in one behaviour (`warn("alpha"); warn("beta");`) are two holders, not one."""
        return (self.behaviour if self.key is None else self.key, self.args)


class Skipped(Exception):
    """Raised by a plugin's phase that did nothing this time by design, neither a success nor a failure
    (not counted, resolves nothing; a start or release is retried): a hold while the serial board is
    away between two reopen attempts, or while the previous call of a service has not returned."""


@dataclass
class ActionStats:
    calls: int = 0
    failures: int = 0
    last_error: str = ""  # the latest failure, kept for the record once resolved (RESOLVED prefix)
    failing: str = ""  # the phase whose latest attempt failed ("start", "input", …); "" when none
    extra: Dict[str, Any] = field(default_factory=dict)


class ActionPlugin:
    """Base class of the built-in plugins; custom plugins need only start/hold/release.

    per_behaviour: every behaviour's start and release is passed on (a log line each);
    otherwise the runner reference-counts: start when the first behaviour using the action
    starts, release when the last one releases.
    period: periodic() is called this often (seconds), whether active or not.
    """

    per_behaviour = False
    period: Optional[float] = None

    def __init__(self, action: ActionDef) -> None:
        self.action = action
        self.name = action.name
        self.params = dict(action.params)
        self.active = False
        self.stats = ActionStats()  # replaced by its runner's, which /diagnostics shows

    def setup(self) -> None:
        """Open publishers, ports, proxies; ActionSetupError for a configuration that cannot work."""

    def claim(self) -> None:
        """A start of this action is about to be submitted: called on the engine's thread for every
        start of one instant before any runner runs; must not block. A plugin that shares a topic by
        priority (its `seat`, from the arbiter) takes it here."""
        seat = getattr(self, "seat", None)
        if seat is not None:
            seat.claim()

    def unclaim(self) -> None:
        """A claimed start was dropped unrun (its release followed it in a full queue)."""
        seat = getattr(self, "seat", None)
        if seat is not None:
            seat.unclaim()

    def start(self, ctx: Context) -> None:
        """The behaviour turned true."""

    def hold(self, ctx: Context) -> None:
        """A tick while active."""

    def release(self, ctx: Context) -> None:
        """The behaviour turned false (or was reset)."""

    def periodic(self) -> None:
        """Called every `period` seconds."""

    def wake(self) -> None:
        """Have periodic() called now (its runner replaces this; a topic handed over by priority)."""

    def close(self) -> None:
        """Release resources at shutdown or when a reload drops the action."""


class CustomPlugin(ActionPlugin):
    """Adapts a robot's own class, named in YAML as 'package.module:Class'.

    The class is built as Class(name, params) and needs start(ctx), hold(ctx), release(ctx);
    setup() and close() are called when it has them.
    """

    def __init__(self, action: ActionDef) -> None:
        super().__init__(action)
        module_name, _, class_name = action.plugin.partition(":")
        if is_standard_library(module_name):
            # a library must not reach code that runs commands ('subprocess:Popen', 'os:system',
            # 'antigravity:…' opens a browser on import): plugins are the robot's own packages
            raise self._error(f"plugin module '{module_name}' is part of Python's standard library; a custom "
                              f"plugin must be a class in the robot's own package")
        try:
            module = importlib.import_module(module_name)
        except Exception as exc:  # ImportError, or the module's own import-time error
            raise self._error(f"cannot import plugin module '{module_name}': "
                              f"{exc.__class__.__name__}: {exc}") from None
        cls = getattr(module, class_name, None)
        if cls is None:
            raise self._error(f"module '{module_name}' has no class '{class_name}'{_CODE_CACHED}")
        missing = [m for m in ("start", "hold", "release") if not callable(getattr(cls, m, None))]
        if not inspect.isclass(cls) or missing:  # checked before anything of it is called
            raise self._error(f"{action.plugin} is not a plugin class: it needs start(ctx), hold(ctx) and "
                              f"release(ctx) methods{_CODE_CACHED}")
        try:
            self.impl = cls(action.name, dict(action.params))
        except Exception as exc:
            raise self._error(f"{action.plugin}({action.name!r}, params) failed: "
                              f"{exc.__class__.__name__}: {exc}{_CODE_CACHED}") from None
        self.per_behaviour = bool(getattr(self.impl, "per_behaviour", False))
        self.period = getattr(self.impl, "period", None)
        self.call_timeout = float(getattr(self.impl, "call_timeout", 0.0) or 0.0)  # how long a call may block

    def _error(self, text: str) -> ActionSetupError:
        """The error as `rubass check` prints a library's: FILE:LINE:COL of its `plugin:` entry, the line, a caret."""
        span = self.action.plugin_span  # where the library's YAML had it (an anchor's, for a merged one)
        message = f"action '{self.name}': {text}"
        if span.line <= 0:  # an action made in code, not read from a library
            return ActionSetupError(message)
        linecache.checkcache(span.file)  # the file as it is now (a reload may have edited it)
        line = linecache.getline(span.file, span.line).rstrip("\n")
        return ActionSetupError(Diagnostic(span, message, line_text=line).render())

    def setup(self) -> None:
        if callable(getattr(self.impl, "setup", None)):
            try:
                self.impl.setup()
            except ActionSetupError as exc:
                raise self._error(str(exc)) from None
            except Exception as exc:  # the robot's own code: a clean error at its entry, not a traceback
                raise self._error(f"{self.action.plugin}.setup() failed: {exc.__class__.__name__}: {exc}") from None

    def start(self, ctx: Context) -> None:
        self.impl.start(ctx)

    def hold(self, ctx: Context) -> None:
        self.impl.hold(ctx)

    def release(self, ctx: Context) -> None:
        self.impl.release(ctx)

    def periodic(self) -> None:
        if callable(getattr(self.impl, "periodic", None)):
            self.impl.periodic()

    def close(self) -> None:
        if callable(getattr(self.impl, "close", None)):
            self.impl.close()


# The built-in plugins (LANGUAGE.md §8, §16): name -> 'module:Class', imported when first used,
# so this pure room never imports ROS itself.
BUILTIN = {
    "publish": "rubass.ros.actions.publish:PublishPlugin",
    "serial": "rubass.ros.actions.serial_port:SerialPlugin",
    "service": "rubass.ros.actions.service:ServicePlugin",
    "limit": "rubass.ros.actions.limit:LimitPlugin",
    "log": "rubass.ros.actions.log:LogPlugin",
}


def make_plugin(action: ActionDef) -> ActionPlugin:
    """The plugin object for a library action (not yet set up)."""
    if action.is_custom:
        return CustomPlugin(action)
    module, _, cls = BUILTIN[action.plugin].partition(":")
    return getattr(importlib.import_module(module), cls)(action)  # type: ignore[no-any-return]


def describe(ctx: Context) -> str:
    rules = f" ({', '.join(ctx.rules)})" if ctx.rules else ""
    return f"behaviour {ctx.behaviour} (line {ctx.line}){rules}"


__all__: List[str] = ["ActionPlugin", "ActionSetupError", "ActionStats", "Skipped", "Context", "CustomPlugin", "make_plugin"]
