"""Process supervision for a command that starts processes: they end when the command does.

- SIGINT, SIGTERM and SIGHUP raise `Interrupted` in the main thread, once: the command's
  `finally` blocks then stop its processes undisturbed (later signals are noted, not raised).
  An ignore inherited from the caller (`nohup`, a script's background job) is kept.
- Every child gets its own process group, and PR_SET_PDEATHSIG: the kernel sends it its stop
  signal when the command dies, even by SIGKILL (the signal follows the *thread* that forked:
  spawn only from the main thread).
- Every process the command starts, by `spawn` or otherwise, inherits a marker in its
  environment (RUBASS_SUPERVISOR=<a fresh uuid>). A small reaper process, in its own session,
  waits on a pipe from the command; if the command vanishes without saying goodbye, it signals
  every process that carries the marker (SIGINT for a recorder, so its bag is closed) and
  SIGKILLs whatever still runs 5 s later. Nobody else's processes (another test, another
  engineer's ROS) carry the marker.
"""
from __future__ import annotations

import atexit
import contextlib
import ctypes
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from typing import IO, Any, Dict, Iterator, List, Optional, Sequence, Union

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
MARKER = "RUBASS_SUPERVISOR"
GRACE = 5.0  # seconds between the stop signal and SIGKILL
_PR_SET_PDEATHSIG = 1

try:
    _prctl: Any = ctypes.CDLL(None, use_errno=True).prctl  # resolved once, before any fork
except (OSError, AttributeError):  # not Linux: the reaper alone
    _prctl = None


class Interrupted(BaseException):
    """A stop signal reached the command (a BaseException, as KeyboardInterrupt: code that
    reports and goes on after `except Exception` lets it through)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name

    @property
    def exit_status(self) -> int:
        """The shell's convention: 128 + the signal (SIGINT 130, SIGTERM 143, SIGHUP 129)."""
        return 128 + self.signum


def die_with_parent(sig: int = signal.SIGTERM) -> Any:
    """A `preexec_fn` for subprocess.Popen: the child gets `sig` when this process (precisely:
    the thread calling Popen) dies. Call Popen from the main thread or a thread that lives on."""
    parent = os.getpid()

    def preexec() -> None:  # in the child, between fork and exec
        if _prctl is not None:
            _prctl(_PR_SET_PDEATHSIG, int(sig), 0, 0, 0)
        if os.getppid() != parent:  # the parent died before prctl took effect
            os._exit(1)
    return preexec


class Supervisor:
    """Starts, tracks and stops a command's processes; see the module docstring.

    Use as a context manager from the main thread: entering installs the signal handlers and
    starts the reaper, leaving stops every process still running and restores the handlers.
    `signals=False` leaves the signal handlers alone (a test harness under pytest): only the
    marker, the reaper and PR_SET_PDEATHSIG."""

    def __init__(self, signals: bool = True) -> None:
        self.signals = signals
        self.marker = uuid.uuid4().hex
        self.signum: Optional[int] = None
        self._raised = False
        self._procs: List[subprocess.Popen] = []
        self._stop_sig: Dict[int, int] = {}
        self._defer = 0
        self._old: Dict[int, Any] = {}
        self._reaper: Optional[subprocess.Popen] = None

    # -- signals -------------------------------------------------------------------------
    def __enter__(self) -> "Supervisor":
        if threading.current_thread() is not threading.main_thread():
            raise RuntimeError("a Supervisor is used from the main thread only")
        self._old_marker = os.environ.get(MARKER)
        with self.deferred(raise_after=False):
            for sig in SIGNALS if self.signals else ():
                old = signal.getsignal(sig)
                if old is signal.SIG_IGN:
                    continue
                self._old[sig] = old
                signal.signal(sig, self._on_signal)
            os.environ[MARKER] = self.marker
            self._start_reaper()
        try:
            self.check()  # a signal that came meanwhile
        except Interrupted:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc: Any) -> None:
        try:
            self.stop_all()
            self._close_reaper()
            # and what was started without spawn (with the marker, from os.environ) or whose Popen a signal
            # kept from its caller: a monitor still starting, a peer a thread ran (benchmarks left them running)
            sweep(self.marker, self._stop_sig)
        finally:
            for sig, old in self._old.items():
                signal.signal(sig, old if old is not None else signal.SIG_DFL)
            self._old.clear()
            if self._old_marker is None:
                os.environ.pop(MARKER, None)
            else:
                os.environ[MARKER] = self._old_marker

    def _on_signal(self, signum: int, frame: Any) -> None:
        if self.signum is not None:
            return  # already stopping: let the cleanup finish
        self.signum = signum
        self.check()

    @contextlib.contextmanager
    def deferred(self, raise_after: bool = True) -> Iterator[None]:
        """A stop signal arriving inside is raised on leaving (raise_after), or only noted in
        `signum` (cleanup code that must not be cut short)."""
        self._defer += 1
        try:
            yield
        finally:
            self._defer -= 1
        if raise_after:
            self.check()

    def check(self) -> None:
        """Raise Interrupted if a stop signal came and has not been raised yet."""
        if self.signum is not None and not self._defer and not self._raised:
            self._raised = True
            raise Interrupted(self.signum)

    # -- processes -----------------------------------------------------------------------
    def env(self, base: Optional[Dict[str, str]] = None) -> Dict[str, str]:
        """`base` (or os.environ) with the marker that makes the reaper recognise ours."""
        return dict(os.environ if base is None else base, **{MARKER: self.marker})

    def spawn(self, args: Sequence[str], env: Optional[Dict[str, str]] = None, stdout: Union[int, IO[Any], None] = None,
              cwd: Optional[str] = None, stop_signal: int = signal.SIGTERM) -> subprocess.Popen:
        """Start a process in its own group; `stop_signal` is what stops it cleanly (SIGINT for
        a recorder). Output goes to `stdout` (None: /dev/null), stderr with it."""
        if threading.current_thread() is not threading.main_thread():
            raise RuntimeError("processes are spawned from the main thread (PR_SET_PDEATHSIG follows the thread)")
        with self.deferred():
            proc = subprocess.Popen(list(args), env=self.env(env), cwd=cwd,
                                    stdout=subprocess.DEVNULL if stdout is None else stdout,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, start_new_session=True,
                                    preexec_fn=die_with_parent(stop_signal))
            self.adopt(proc, stop_signal)
        return proc

    def adopt(self, proc: subprocess.Popen, stop_signal: int = signal.SIGTERM) -> None:
        """Track a process started elsewhere (with this supervisor's marker in its environment,
        and in its own group), to stop it with the others."""
        if proc not in self._procs:
            self._procs.append(proc)
        self._stop_sig[proc.pid] = int(stop_signal)
        self._tell(f"add {proc.pid} {int(stop_signal)}")

    def stop(self, procs: Sequence[subprocess.Popen], timeout: float = GRACE) -> None:
        """Send each process group its stop signal, wait for each process; SIGKILL the group
        of one that does not exit in `timeout` s. A stop signal meanwhile is only noted."""
        with self.deferred(raise_after=False):
            for p in procs:
                if p.poll() is None:
                    _signal_group(p, self._stop_sig.get(p.pid, signal.SIGTERM))
            for p in procs:
                try:
                    p.wait(timeout)
                except subprocess.TimeoutExpired:
                    _signal_group(p, signal.SIGKILL)
                    p.wait()
                if p in self._procs:
                    self._procs.remove(p)
                    self._tell(f"del {p.pid}")

    def stop_all(self) -> None:
        """Stop every process still known, the latest started first."""
        self.stop(list(reversed(self._procs)))

    # -- the reaper ----------------------------------------------------------------------
    def _start_reaper(self) -> None:
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the checkout
        code = f"import sys; sys.path.insert(0, {root!r}); from rubass_experiments.procs import reap; reap({self.marker!r})"
        self._reaper = subprocess.Popen([sys.executable, "-c", code], stdin=subprocess.PIPE, env=self.env(),
                                        stdout=subprocess.DEVNULL, start_new_session=True, text=True)

    def _tell(self, line: str) -> None:
        if self._reaper is not None and self._reaper.stdin is not None:
            try:
                self._reaper.stdin.write(line + "\n")
                self._reaper.stdin.flush()
            except (BrokenPipeError, OSError):
                pass

    def _close_reaper(self) -> None:
        if self._reaper is None:
            return
        self._tell("bye")
        with contextlib.suppress(OSError):
            assert self._reaper.stdin is not None
            self._reaper.stdin.close()
        try:
            self._reaper.wait(GRACE)
        except subprocess.TimeoutExpired:
            self._reaper.kill()
            self._reaper.wait()
        self._reaper = None


def supervise_script(prog: str) -> Supervisor:
    """For a script whose code knows nothing of Interrupted (a benchmark): a Supervisor for the
    rest of the process. A stop signal unwinds the script's `finally` blocks (which stop its
    processes), then it exits 128 + the signal with one line on stderr, no traceback; every
    process still running (or started without `spawn`, with the marker) is stopped at exit."""
    sup = Supervisor().__enter__()
    atexit.register(sup.__exit__, None, None, None)
    default_hook = sys.excepthook

    def hook(kind: Any, value: BaseException, tb: Any) -> None:
        if not isinstance(value, Interrupted):
            default_hook(kind, value, tb)
            return
        print(f"{prog}: interrupted by {value.name}", file=sys.stderr)
        with contextlib.suppress(Exception):
            sys.stdout.flush()
            sup.__exit__(None, None, None)
        os._exit(value.exit_status)
    sys.excepthook = hook
    return sup


def _signal_group(proc: subprocess.Popen, sig: int) -> None:
    """Signal the process's group, or the process alone when it leads none."""
    try:
        os.killpg(proc.pid, sig)
    except (ProcessLookupError, PermissionError):
        with contextlib.suppress(OSError):
            proc.send_signal(sig)


def _ours(marker: str) -> Dict[int, int]:
    """pid -> process group of every live process (but this one) that carries the marker."""
    tag = f"{MARKER}={marker}".encode()
    found: Dict[int, int] = {}
    for name in os.listdir("/proc"):
        if not name.isdigit() or int(name) == os.getpid():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as fh:
                stat = fh.read()
            fields = stat[stat.rindex(b")") + 2:].split()
            if fields[0] == b"Z":
                continue
            pgid = int(fields[2])
            with open(f"/proc/{name}/environ", "rb") as fh:
                if tag in fh.read().split(b"\0"):
                    found[int(name)] = pgid
        except (OSError, ValueError, IndexError):
            continue
    return found


def reap(marker: str) -> None:
    """The reaper's main: follow 'add PGID SIG' / 'del PGID' on stdin; at end of input
    without 'bye' (the command died), stop every process with the marker: with its group's
    stop signal (SIGTERM when not told), then SIGKILL after GRACE seconds."""
    for sig in (signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)  # a terminal's Ctrl-C or hangup is for the command
    groups: Dict[int, int] = {}
    for line in sys.stdin:
        word = line.split()
        if word[:1] == ["bye"]:
            return
        if word[:1] == ["add"] and len(word) == 3:
            groups[int(word[1])] = int(word[2])
        elif word[:1] == ["del"] and len(word) == 2:
            groups.pop(int(word[1]), None)
    sweep(marker, groups)


def sweep(marker: str, stop_signals: Optional[Dict[int, int]] = None) -> None:
    """Stop every process (but this one) that carries the marker: its group's stop signal from
    `stop_signals` (by group leader's pid; SIGTERM when not there), then SIGKILL after GRACE seconds."""
    found = _ours(marker)
    if not found:
        return
    for pid, pgid in found.items():
        with contextlib.suppress(OSError):
            os.kill(pid, (stop_signals or {}).get(pgid, signal.SIGTERM))
    end = time.monotonic() + GRACE
    while time.monotonic() < end and _ours(marker):
        time.sleep(0.1)
    for pid in _ours(marker):
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)
