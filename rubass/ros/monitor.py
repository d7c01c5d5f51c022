"""The rubass monitor node: enforces a RuBaSS spec on a live ROS 1 system.

ROS API
-------
Parameters (private)
    ~spec (string, required)      the spec file (.rbs)
    ~actions (list of strings)    action libraries to load besides the spec's imports
    ~rate (Hz, default 50)        scheduler ticks: `hold`, `age`/`frequency` re-evaluation, heartbeat
    ~node_rate (Hz, default 10)   node samples for alive(), cpu(), memory()
    ~diagnostics_rate (Hz, 1)     /diagnostics publications
    ~master_rate (Hz, default 4)  checks that the master still knows the monitor (re-registers
                                  after a master restart: docs/monitor.md)
    ~overload_actions (list)      actions to run while messages are dropped or seen 0.5 s late (fail safe)
    ~queue_size (10 to 10000000, default 100000)  messages the engine's queue holds (and 256 MiB
                                  of message bytes)
    ~error_actions (list)         actions to run while a field cannot be read as the spec needs (fail safe)
    ~state_file (string)          latched actions kept across the monitor's restarts (default
                                  $ROS_HOME/rubass/NODE.latches.json for a master on this machine
                                  at port 11311, else NODE.PORT.latches.json, or NODE.HOST.PORT.
                                  latches.json for another machine's master; false: off)
    ~nice (int, -20 to 19)        the threads' scheduling priority, set at start (priority.py)
Subscribes
    every topic the spec names, whatever its type (rospy.AnyMsg, tcp_nodelay)
    /rubass/agent_samples (std_msgs/String)  the agents' reports: cpu and memory of nodes on
                                  other hosts (docs/multihost.md)
Publishes
    /diagnostics (diagnostic_msgs/DiagnosticArray)  one status per entity, one for the monitor
    ~events (std_msgs/String)     one JSON object per behaviour start and release (docs/monitor.md)
    ~heartbeat (std_msgs/Header)  at the tick rate, from the engine's thread (withheld while no spec
                                  is enforced, and while a latch restored from the state file names an
                                  action the spec does not declare, until ~reset)
    ~node_samples (std_msgs/String)  each node sample as JSON, so that recordings can replay them
    and whatever the spec's publish actions publish
Services
    ~reload (std_srvs/Trigger)    re-read spec and libraries; a broken spec is rejected
    ~reset (std_srvs/Trigger)     release latched actions whose cause is gone
Signals
    SIGHUP reloads as ~reload; SIGINT/SIGTERM release non-latched actions, close ports, exit 0
"""
from __future__ import annotations

import queue
import signal
import threading
import time
from typing import Any, Callable, Dict, List, Optional, Tuple

import genpy
import rosgraph
import rospy
from std_msgs.msg import String
from std_srvs.srv import Trigger, TriggerResponse

from ..engine import Engine, Event
from ..engine.loop import EngineLoop, Message, NodeSample
from ..engine.unknowns import rule_reasons, snapshot as store_snapshot
from ..lang import SpecError, load_spec
from ..lang.errors import counted, in_text_order
from ..lang.library import priority_conflicts
from ..lang.model import CheckedSpec
from ..actions import status as status_mod
from ..actions.base import ActionSetupError, make_plugin
from .agentbook import AGENT_TOPIC, AgentBook
from .agentbook import decode as decode_agent_report
from ..actions.runner import ActionRunner
from ..actions.dispatch import Dispatcher
from .master_watch import MONITOR_STARTING_UNREACHABLE, MONITOR_UNREACHABLE, MasterWatch
from .libtypes import after_check, render_failed_check
from .livecheck import LiveTypeCheck
from .nodes import NodeSampler
from .outputs import Outputs
from ..actions.overload import LATE, QUEUE, SOCKETS, OverloadGuard, late_status, lateness
from .clockjump import ClockJump
from ..actions.errorguard import ErrorGuard
from ..actions.keeper import LatchKeeper
from ..actions.latches import Latch, LatchFile, undeclared
from .params import MonitorConfig, relative_note, spec_warnings
from .gcfreeze import freeze_heap
from .timerslack import exact_timers
from .priority import describe, thread_nice_values
from .exiting import EXIT_GRACE, exit_within
from .reloading import ConfigError, Reloading, StartupError, said_if_slow
from . import receiver
from .topics import TopicWatcher, message_bytes, ros_now

_mono = time.monotonic


def _log(level: str, text: str) -> None:
    {"debug": rospy.logdebug, "info": rospy.loginfo, "warn": rospy.logwarn, "error": rospy.logerr}[level](text)


def _ros_now() -> float:
    return ros_now()


def _register_aside(what: str, register: Callable[[], Any]) -> None:
    """Register a service or subscription on a thread of its own: rospy retries it on the calling thread,
    holding its lock, until the master answers, and the start must go on (enforcing) meanwhile."""
    def run() -> None:
        try:
            register()
        except Exception as exc:  # noqa: BLE001 - the rules are enforced either way; the log says what is missing
            _log("error", f"rubass: cannot {what}: {exc.__class__.__name__}: {exc}")

    threading.Thread(target=run, name="rubass-register", daemon=True).start()


class Monitor(Reloading):
    def __init__(self, config: MonitorConfig) -> None:
        self.config = config
        self.nice_refused = False  # ~nice was asked for and not permitted (node.py sets it)
        self.reloads = 0
        self.rejected = 0
        self.last_reload_error = ""
        self._reload_lock = threading.RLock()
        self._reload_wanted = threading.Event()  # a SIGHUP asked for a reload (reload_thread)
        self.coalesced = 0
        self._stopping = False
        self._exit = threading.Event()
        self._starting = False  # setup() runs: a reload asked meanwhile waits for its end (_reload_deferred)
        self._start_lock = threading.Lock()
        self._reload_deferred: List[str] = []  # what asked for it ("SIGHUP", "service")
        self.spec: Optional[CheckedSpec] = None  # None while not enforcing (no usable spec yet)
        self.runners: Dict[str, ActionRunner] = {}
        self.retired_failures = 0  # failed attempts of runners a reload replaced: `failed action attempts` is since start
        self.loop: Optional[EngineLoop] = None
        self.load_error = ""  # why the monitor is not enforcing, while it is not
        self.enforcing = False  # the engine's thread runs (ticks, deadlines): set once, at the end of _enforce
        self.withheld: List[Latch] = []  # latches on actions the spec does not declare: no ~heartbeat meanwhile

    # -- start-up ------------------------------------------------------------------------
    def load(self) -> Tuple[CheckedSpec, Dict[str, ActionRunner]]:
        """Check the spec and build its actions; StartupError with every problem found."""
        try:
            spec = load_spec(self.config.spec, self.config.actions)
        except SpecError as exc:  # with its libraries' errors, as `rubass check` prints them: all in one run
            raise StartupError(self._failed_text(exc)) from None
        self._check_overload_actions(spec)
        self._check_actions(spec)
        for w in spec_warnings(spec.warnings, self.config):
            rospy.logwarn("rubass: %s", w.render(spec.sources))
        with said_if_slow("rubass: setting up the actions takes over a second (their publishers register with the "
                          "master, which may not be answering; a serial port opens): NO RULE IS ENFORCED until it is "
                          "done"):
            return spec, self._runners(spec, {})

    def _failed_text(self, exc: SpecError) -> str:
        """Every error of a spec that did not check, as `rubass check` prints them; where a relative
        ~spec or ~actions path was looked for when a file it names is missing."""
        text = render_failed_check(exc, self.config.spec, self.config.actions)
        note = relative_note(self.config)
        return f"{text}\n{note}" if note else text

    def _check_overload_actions(self, spec: CheckedSpec) -> None:
        missing = [a for a in self.config.overload_actions if a not in spec.actions]
        if missing:
            raise ConfigError(f"{spec.path}: ~overload_actions names {', '.join(missing)}, which the spec does not "
                               f"declare (add 'action primitive {', '.join(missing)};')")
        missing = [a for a in self.config.error_actions if a not in spec.actions]
        if missing:
            raise ConfigError(f"{spec.path}: ~error_actions names {', '.join(missing)}, which the spec does not "
                              f"declare (add 'action primitive {', '.join(missing)};')")

    @staticmethod
    def _check_actions(spec: CheckedSpec) -> None:
        """Two actions of one priority on one topic (§16, across libraries, names resolved), and publish
        and service actions against the installed definitions: every error at its YAML line, at once."""
        errors = priority_conflicts(spec.actions.values(), rospy.resolve_name) + after_check(spec, None)[0]
        if errors:
            raise StartupError("\n".join(d.render(spec.sources) for d in in_text_order(errors)))

    def _runners(self, spec: CheckedSpec, keep: Dict[str, ActionRunner]) -> Dict[str, ActionRunner]:
        """Runners for the spec's actions, reusing those whose definition did not change."""
        out: Dict[str, ActionRunner] = {}
        try:
            for name, action in spec.actions.items():
                old = keep.get(name)
                if old is not None and old.plugin.action == action and old.plugin.params == dict(action.params):
                    out[name] = old
                    continue
                plugin = make_plugin(action)
                plugin.setup()
                out[name] = ActionRunner(plugin, _log)
        except ActionSetupError as exc:
            for name, runner in out.items():
                if keep.get(name) is not runner:
                    runner.plugin.close()
            raise StartupError(str(exc)) from None
        return out

    def setup(self) -> None:
        """ROS scaffolding, then enforcement. A spec that cannot be used leaves the monitor up but not
        enforcing: ERROR in /diagnostics, no ~heartbeat, until a reload brings a usable one."""
        self.outputs = Outputs()
        self.dispatcher = Dispatcher({}, self.outputs.event, _ros_now, rospy.resolve_name)
        self.overload = OverloadGuard(self.config.overload_actions, 1.0, _log, self.outputs.event)
        self.keeper = LatchKeeper(LatchFile(self.config.state_file, self.config.spec, rosgraph.get_master_uri()),
                                  _log, self.outputs.event)
        self.error_guard = ErrorGuard(self.config.error_actions, _log, self.outputs.event)
        self.clock_jump = ClockJump(self.dispatcher, _log,
                                    lambda engine: self.keeper.save(engine, self.dispatcher.orphans, self._fail_safes()))
        # our own SIGINT/SIGTERM from here: release actions while publishers still work, then stop rospy
        # (after rospy's own handler, publish() silently does nothing); one while the spec is read (a
        # large one takes a second) ends the monitor once it is read, unregistered from the master
        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, self.request_stop)
        # SIGHUP before the spec is read: one that comes while it is read, or a SIGHUP or ~reload while the
        # monitor waits for the first /clock, is run as soon as it enforces (the file may have changed)
        self._starting = True
        threading.Thread(target=self.reload_thread, name="rubass-reload", daemon=True).start()
        signal.signal(signal.SIGHUP, lambda signum, frame: self.request_reload())
        try:
            spec, runners = self.load()
        except ConfigError:
            raise
        except StartupError as exc:
            self._not_enforcing(str(exc))
        self._install_control()  # the services once the spec is read, as before: ~reset up means read
        freeze_heap()  # the one long collection (15-18 ms here), before anything is enforced (gcfreeze.py)
        if not self.load_error and not self._exit.is_set():
            self._enforce(spec, runners)
            freeze_heap()  # the engine, subscriptions and runners too: a short collection now
        with self._start_lock:
            self._starting = False
            asked = ", ".join(self._reload_deferred)
        if asked and not self._exit.is_set():
            self.request_reload(f"{asked}, asked while the monitor started")

    def request_stop(self, signum: int = 0, frame: object = None) -> None:
        """Stop the monitor (SIGINT, SIGTERM): actions released on the main thread, which run() ends.
        Before it enforces, the start stops at its next step; one that waits for a master that does not
        answer (an action's publisher registering) is cut after EXIT_GRACE seconds."""
        self._exit.set()
        if not self.enforcing and not self._stopping:
            exit_within(EXIT_GRACE, 0, "nothing was enforced", "the monitor's start did not stop")

    def _not_enforcing(self, error: str) -> None:
        self.load_error = error
        rospy.logerr("rubass: NOT ENFORCING ANY RULE: cannot use the spec:\n%s\nThe monitor stays up without "
                     "~heartbeat (a watchdog fed by it stops the robot); fix the file, then SIGHUP or "
                     "rosservice call ~reload", error)

    def _status_failed(self, exc: Exception) -> str:
        """An ERROR status saying why the full one is missing (e.g. the engine's thread stalled); the why."""
        why = "the engine's thread did not answer (stalled?)" if isinstance(exc, (queue.Empty, queue.Full)) \
            else f"{exc.__class__.__name__}: {exc}"
        if isinstance(exc, (queue.Empty, queue.Full)) and self.overload.active:  # it answers behind the queue
            why = (f"the engine's thread did not answer: OVERLOADED, {self.overload.reason}: running "
                   f"{', '.join(self.overload.actions)}")
        try:
            self.outputs.status([status_mod.Entry("rubass: monitor", status_mod.ERROR, f"STATUS UNAVAILABLE: {why}",
                                                  [("spec", self.config.spec)])], _ros_now())
        except Exception:  # publishing itself failed: the log line is all there is
            pass
        return why

    def _why_not(self) -> str:
        """Why the monitor is not enforcing (before its engine runs)."""
        if self.load_error:
            return self.load_error
        return "waiting for the first /clock message (use_sim_time)" if self.spec is not None else "starting"

    def _first_time(self) -> float:
        """ROS time now; with use_sim_time, the first /clock message's (watching starts then, not at 0)."""
        now = _ros_now()
        if now == 0.0 and rospy.get_param("/use_sim_time", False):
            rospy.logwarn("rubass: use_sim_time is set and no /clock message has come yet: waiting for the "
                          "first one before watching (no rule is enforced and no ~heartbeat is published "
                          "meanwhile; latched actions are held)")
            started = time.monotonic()
            due = started  # /diagnostics says so meanwhile, on the wall clock (ROS time stands at 0)
            while now == 0.0 and not self._exit.is_set() and not rospy.is_shutdown():
                if time.monotonic() >= due:
                    due += 1.0 / self.config.diagnostics_rate
                    held = [f"{', '.join(r.actions)} ({r.holder})" for r in self.keeper.restored]
                    try:
                        self.outputs.status(status_mod.waiting_for_clock(self.config.spec, time.monotonic() - started,
                                                                         held), time.time())
                    except Exception as exc:  # noqa: BLE001 - the wait goes on; the log says why
                        rospy.logerr_throttle(10, f"rubass: status failed: {exc.__class__.__name__}: {exc}")
                    if time.monotonic() - started >= 10.0:  # long enough for a simulator to start
                        rospy.logerr_throttle(60, f"rubass: NOT ENFORCING ANY RULE: use_sim_time is true and no /clock "
                                                  f"message came for {time.monotonic() - started:.0f} s (is "
                                                  f"/use_sim_time left set on a real robot?)")
                self._exit.wait(0.01)
                now = _ros_now()
            if now != 0.0:  # not when a stop signal ended the wait
                rospy.loginfo("rubass: first /clock message: %.3f s", now)
        return now

    def _on_events(self, events: List[Any], cause: Any) -> None:
        """On the engine's thread: the latch state is written before a latched action is dispatched."""
        engine = self.loop.engine  # type: ignore[union-attr]
        events = self.clock_jump.take_over(engine, events)  # held across a clock jump: no second start
        if self.keeper.changes(engine, events):
            self.keeper.save(engine, self.dispatcher.orphans, self._fail_safes())
        self.dispatcher.handle(engine, events, cause)

    def _fail_safes(self, starting: bool = False, error_starting: bool = False) -> List[List[str]]:
        out = [self.overload.actions] if self.overload.active or starting else []
        return out + ([self.error_guard.actions] if self.error_guard.active or error_starting else [])

    def _data_errors(self, engine: Engine) -> List[str]:
        """Fields that cannot be read as the spec needs, now (on the engine's thread)."""
        return self.watcher.data_errors() + [f"topic {t}: {m}" for (t, _), m in sorted(engine.field_errors.items())]

    def _enforce(self, spec: CheckedSpec, runners: Dict[str, ActionRunner]) -> None:
        """Start the actions, restore latches, wait for the clock, then the first evaluation."""
        self.spec, self.runners, self.dispatcher.runners = spec, runners, runners
        self.keeper.file.spec_path = spec.path
        for runner in runners.values():
            runner.start_thread()
        self.keeper.restore(spec.actions, runners, _ros_now())  # before the first tick
        self._withhold(spec)
        now = self._first_time()
        if self._exit.is_set():  # stopped while waiting for /clock: nothing is enforced (latched actions stay)
            return
        engine = Engine(spec, now)
        # inline: a message is evaluated on the thread that received it when the engine is free
        # (no hand-off to the engine's thread per message; issue 17)
        self.loop = EngineLoop(engine, _ros_now, self.config.rate, self._on_events,
                               max_queue=self.config.queue_size, tick_hook=self._tick, on_clock_jump=self.clock_jump,
                               inline=True, on_error=self._engine_error)
        hold = getattr(engine, "hold_actions", None)  # an engine that knows outside holders: active(a) sees them
        for latch in self.keeper.restored if hold is not None else []:
            self._on_events(hold(latch.actions, f"restored: {latch.holder}", now), "reload")
        self._on_events(engine.evaluate_all(now), "reload")
        self.keeper.save(engine, self.dispatcher.orphans, self._fail_safes())
        # one thread reads every watched topic's connections (issue 17; rospy's threads where it cannot)
        reader = receiver.install(_log) if self.config.receiver == "one_thread" else None
        self.watcher = TopicWatcher(self._on_message, _log, self._on_spellings, reader)
        self.watcher.sync(spec)
        self.livecheck = LiveTypeCheck(_log)  # the spec against the types its topics turn out to carry
        self.agents = AgentBook()  # cpu and memory of nodes on other hosts, from their agents
        # the nodes of other hosts read unknown, and say why, until it is registered
        _register_aside(f"subscribe to {AGENT_TOPIC}", lambda: rospy.Subscriber(
            AGENT_TOPIC, rospy.AnyMsg, self._on_agent, queue_size=100, tcp_nodelay=True))
        self.sampler = self._sampler(spec)
        self.load_error = ""
        rospy.loginfo("rubass: enforcing %s (%s)", spec.path, ", ".join(  # distinct topics
            counted(n, noun) for n, noun in ((len(spec.rules), "rule"), (len(spec.behaviours), "behaviour"),
                                             (len(self.watcher.topics), "topic"), (len(spec.nodes), "node"))))
        threading.Thread(target=self._engine_thread, name="rubass-engine", daemon=True).start()
        self.enforcing = True

    def _install_control(self) -> None:
        """Services and the master watch: up whether or not the spec can be enforced. The services
        register on a thread of their own: the start goes on while the master does not answer."""
        self.master_watch = MasterWatch(rospy.get_caller_id(), rospy.core.get_node_uri(), rosgraph.get_master_uri(),
                                        1.0 / self.config.master_rate, _log, unreachable=self._unreachable_means)
        self.master_watch.start()
        _register_aside("offer ~reload and ~reset", lambda: (  # SIGHUP reloads meanwhile
            rospy.Service("~reload", Trigger, lambda req: TriggerResponse(*self.reload("service"))),
            rospy.Service("~reset", Trigger, lambda req: TriggerResponse(*self.reset()))))

    def _unreachable_means(self) -> str:
        """What a master that stops answering means for the robot, as the monitor stands."""
        if self.enforcing:  # not `loop`: it is set a second before, while the topics are subscribed
            return MONITOR_UNREACHABLE
        if self.load_error:
            return ("NO RULE IS ENFORCED (the spec cannot be used, see above); nodes started now cannot connect to the "
                    "monitor until the master is back")
        return MONITOR_STARTING_UNREACHABLE

    def _withhold(self, spec: CheckedSpec) -> None:
        """A latch of the previous run on an action this spec does not declare cannot be held: the
        ~heartbeat is withheld (a watchdog fed by it keeps the robot stopped) until ~reset, and the
        latch stays in the state file meanwhile (docs/failure-modes.md)."""
        path = self.keeper.file.path
        self.withheld = undeclared(path, {n: bool(a.latch) for n, a in spec.actions.items()}) if path else []
        self.keeper.file.kept = list(self.withheld)
        if self.withheld:
            rospy.logerr("rubass: %s: NO ~heartbeat until ~reset: the previous run latched %s, which this spec does "
                         "not declare (renamed or removed?), so the monitor cannot hold it; a watchdog fed by "
                         "~heartbeat keeps the robot stopped (ISO 3691-4: no automatic restart after a protective "
                         "stop)", path, self._withheld_text())

    def _nice(self) -> str:
        """The threads' nice value(s), and ~nice if it was asked for and refused (priority.py)."""
        return describe(thread_nice_values(), self.config.nice, self.nice_refused)

    def _withheld_text(self) -> str:
        return "; ".join(f"{', '.join(w.actions)} ({w.holder})" for w in self.withheld)

    def _tick(self, now: float) -> None:
        """On the engine's thread at each tick: the heartbeat (unless withheld, or the monitor sees its
        messages LATE or later), then the overload check."""
        loop = self.loop
        assert loop is not None
        reader = self.watcher.receiver
        read = reader.take_behind() if reader is not None else 0.0  # how late the receiver reads
        waited = loop.take_waited()  # and how long messages wait in the engine's queue after it
        behind, where = (waited, QUEUE) if waited > read else (read, SOCKETS)
        # a busy engine still ticks between messages: a beat then would feed the robot's watchdog
        # while the rules run seconds behind (a reviewer's finding), so none while it is late
        if not self.withheld and behind < LATE:
            self.outputs.beat(now)
        was = self.overload.active
        if behind >= LATE and not self.overload.actions:  # with them, the fail-safe's start says it
            what, waits = lateness(behind, where)
            rospy.logwarn_throttle(10, f"rubass: {what} ({waits}: the monitor cannot keep up); no ~overload_actions "
                                       f"are set; no ~heartbeat while it is late")
        if not was and self.overload.would_start(loop.dropped, behind):  # written before the fail-safe runs
            self.keeper.save(loop.engine, self.dispatcher.orphans, self._fail_safes(starting=True))
        self.overload.check(loop.dropped, now, self.dispatcher.runners, lambda name: loop.engine.spec.actions[name].latch,
                            loop.dropped_by_topic, behind, where)
        if was and not self.overload.active:
            self.keeper.save(loop.engine, self.dispatcher.orphans, self._fail_safes())
        self.clock_jump.check(loop.engine, now)
        if self.keeper.file.error:  # a latch state that could not be written (a full disk): tried again
            self.keeper.retry(loop.engine, self.dispatcher.orphans, self._fail_safes(), now)
        if self.error_guard.actions:
            errors = self._data_errors(loop.engine)
            was = self.error_guard.active
            if errors and not was:  # written before the fail-safe runs
                self.keeper.save(loop.engine, self.dispatcher.orphans, self._fail_safes(error_starting=True))
            self.error_guard.check(errors, now, self.dispatcher.runners,
                                   lambda name: loop.engine.spec.actions[name].latch)
            if was and not self.error_guard.active:
                self.keeper.save(loop.engine, self.dispatcher.orphans, self._fail_safes())

    def _sampler(self, spec: CheckedSpec, previous: Optional[NodeSampler] = None) -> NodeSampler:
        """The node sampler of `spec`'s nodes; `previous`: the one a reload replaces (what it knew is kept)."""
        nodes = [(n, rospy.resolve_name(n)) for n in sorted(spec.nodes)]
        sampler = NodeSampler(nodes, self._on_node, _ros_now, 1.0 / self.config.node_rate, rospy.get_name())
        sampler.remote = lambda node, host, pid: self.agents.lookup(node, host, pid, time.monotonic())
        if previous is not None:
            sampler.carry(previous)
        sampler.start()
        return sampler

    def _on_message(self, topic: str, now: float, msg: Any, wall: float, size: int) -> None:
        self.loop.submit(Message(topic, now, msg, wall, size, (), _mono()))

    def _on_spellings(self, topics: Tuple[str, ...], now: float, msg: Any, wall: float, size: int) -> None:
        self.loop.submit(Message(topics[0], now, msg, wall, size, topics[1:], _mono()))

    def _on_agent(self, raw: Any) -> None:
        """An agent's report (subscribed as rospy.AnyMsg, as the spec's topics are: a spec may name
        the agents' topic, and rospy gives both subscribers the first one's class)."""
        header = getattr(raw, "_connection_header", None) or {}
        try:
            if header.get("type", String._type) != String._type:
                raise ValueError(f"a {header.get('type')} message from {header.get('callerid', '?')}, not {String._type}")
            msg = String()
            msg.deserialize(message_bytes(raw))
            self.agents.update(decode_agent_report(msg.data), time.monotonic(), header.get("callerid") or None)
        except (ValueError, genpy.DeserializationError) as exc:
            rospy.logwarn_throttle(10, f"rubass: ignoring a bad report on {AGENT_TOPIC}: {exc}")

    def _on_node(self, node: str, now: float, alive: Any, cpu: Any, memory: Any) -> None:
        self.loop.submit(NodeSample(node, now, alive, cpu, memory))
        self.outputs.node_sample(node, now, alive, cpu, memory)

    # -- running -------------------------------------------------------------------------
    def run(self) -> None:
        period = 1.0 / self.config.diagnostics_rate
        while not rospy.is_shutdown() and not self._exit.is_set():
            try:
                self.publish_status()
            except Exception as exc:  # the status must never take the monitor down, nor go silent
                rospy.logerr_throttle(10, f"rubass: status unavailable: {self._status_failed(exc)}")
            self._exit.wait(period)
        self.shutdown()
        rospy.signal_shutdown("rubass monitor stopped")

    @staticmethod
    def _engine_error(exc: Exception) -> None:
        """A bug met while evaluating inline, on a subscriber's thread: logged, and enforcement goes on."""
        rospy.logerr_throttle(1, f"rubass: engine step failed: {exc.__class__.__name__}: {exc}")

    def _engine_thread(self) -> None:
        loop = self.loop
        assert loop is not None
        exact_timers()  # deadlines wake this thread: not up to 50 µs late (docs/engine.md)
        while not self._stopping:
            try:
                loop.step(max_wait=0.1)
            except Exception as exc:  # a bug must not silently stop enforcement: log and go on
                rospy.logerr_throttle(1, f"rubass: engine step failed: {exc.__class__.__name__}: {exc}")

    # -- control -------------------------------------------------------------------------
    def reset(self) -> Tuple[bool, str]:
        now = _ros_now()
        loop = self.loop
        if loop is None:
            return False, f"not enforcing any rule: {self._why_not()}"

        def do(engine: Engine) -> int:
            events = engine.reset(now)
            self._on_events(events, "reset")  # a latched start it causes is written before it is dispatched
            n = len(self.dispatcher.orphans)
            for b, _ in self.dispatcher.orphans:  # ~events pairs their starts (clock jump, reload)
                self.dispatcher.report_event(Event(now, "release", b.index), b, (), "reset")
            self.dispatcher.release_orphans(now)
            self.clock_jump.reset()
            n += self.overload.reset(now, self.dispatcher.runners)
            n += self.keeper.reset(self.dispatcher.runners, now)
            n += self.error_guard.reset(now, self.dispatcher.runners)
            n += len(self.withheld)  # the heartbeat resumes: the latch on an undeclared action ends
            self.withheld = self.keeper.file.kept = []
            self.keeper.save(engine, self.dispatcher.orphans, self._fail_safes())
            return sum(e.kind == "release" for e in events) + n

        released = loop.call(do)
        still = loop.call(lambda engine: [engine.spec.behaviours[i - 1].label for i in engine.active_behaviours()
                                          if engine.spec.behaviours[i - 1].latched])  # what ~reset concerns
        msg = f"released {released} latched behaviour{'s' if released != 1 else ''}"
        if still:
            msg += f"; latched and still active (cause present): {', '.join(still)}"
        rospy.loginfo("rubass: reset: %s", msg)
        return True, msg

    def publish_status(self) -> None:
        if self.loop is None:
            self.outputs.status(status_mod.not_enforcing(self.config.spec, self._why_not(), self.reloads,
                                                         self.rejected), _ros_now())
            return
        loop = self.loop

        def snapshot(engine: Engine) -> Tuple[Dict[str, Any], List[int], Dict[Tuple[str, str], str], Any, Any]:
            rules = dict(engine.store.rules)
            unknown = any(rules.get(r.key) is not True and rules.get(r.key) is not False for r in engine.spec.rules)
            # the store only when a rule is unknown: it is copied here (µs), walked on this thread
            return (rules, engine.active_behaviours(), dict(engine.field_errors), engine.spec,
                    store_snapshot(engine.store) if unknown else None)

        rules, active, field_errors, engine_spec, store = loop.call(snapshot)
        # why unknown rules are so, from the values of the same instant as `rules`: at the status rate
        # only, never per message, and never holding the engine
        computed = rule_reasons(engine_spec, store, field_errors) if store is not None else {}
        data_errors = loop.call(self._data_errors)
        self.livecheck.use(self.spec, self.config.actions)  # after a reload: the new spec
        self.livecheck.note(self.watcher.carried_types())
        topics = {name: {"messages": s.messages, "errors": s.errors, "type": s.type, "resolved": s.resolved}
                  for s in self.watcher.status() for name in (s.spec_name,) + s.aliases}  # every spelling
        nodes = {s.spec_name: {"why": s.why, "resolved": s.resolved} for s in self.sampler.status.values()}
        failures = self.retired_failures + sum(r.stats.failures for r in self.runners.values())
        lat = sorted(self.dispatcher.latencies)
        reader = self.watcher.receiver
        monitor: Dict[str, Any] = {
            "spec": self.spec.path, "reloads": self.reloads, "rejected reloads": self.rejected,
            "coalesced reload requests": self.coalesced,
            "last reload error": self.last_reload_error, "dropped messages": loop.dropped,
            "overloaded": "running " + ", ".join(self.overload.actions) if self.overload.active else "no",
            "overload cause": self.overload.reason if self.overload.active else "none",
            "failed action attempts": failures,  # every one ever, for the record (no action name has a space)
            "master": self.master_watch.state, "master re-registrations": self.master_watch.reregistrations,
            "connections made again": self.master_watch.lost.reconnected,
            "reaction latency p50 ms": f"{lat[len(lat) // 2] * 1000:.3f}" if lat else "n/a",
            "nice": self._nice(),
            "receiving": self.watcher.receiving(self.config.receiver),
            "read late": late_status(reader.take_behind(1) if reader is not None else 0.0, loop.take_waited(1)),
            "agents": self.agents.summary(time.monotonic()),
            "silent agents": ", ".join(self.agents.silent(time.monotonic())) or "none",
            "agents claiming one host": "; ".join(self.agents.conflicts(time.monotonic())) or "none",
        }
        for name, r in self.runners.items():
            if r.stats.last_error:
                monitor[f"action {name}"] = r.stats.last_error
        failing = status_mod.failing_of({name: r.stats for name, r in self.runners.items()})
        monitor.update(self.keeper.status())
        withheld = self.withheld
        if withheld:  # ERROR: the robot is held by the watchdog, not by the monitor
            monitor["heartbeat"] = "WITHHELD until ~reset"
            monitor["latch state error"] = "; ".join(  # keeps what else is wrong with the file
                [f"NO ~heartbeat until ~reset: the previous run latched {self._withheld_text()}, which the spec "
                 f"does not declare (cannot be held)"] + [e for e in [monitor.get("latch state error", "")] if e])
        monitor["clock jumps back"] = loop.clock_jumps
        if loop.dropped_by_topic:
            monitor["dropped by topic"] = ", ".join(f"{t} {n}" for t, n in sorted(loop.dropped_by_topic.items()))
        monitor["last start"] = getattr(self.dispatcher, "last_start", "none")  # with its witnesses
        orphans = list(self.dispatcher.orphans)  # latched behaviours carried over a reload or a clock jump
        if orphans:
            monitor[status_mod.HELD[0]] = "; ".join(
                f"{', '.join(a.name for a in b.actions)} ({b.label}, line {b.span.line}, latched before the "
                f"reload or clock jump)" for b, _ in orphans)
        monitor["data errors"] = "; ".join(data_errors) or "none"
        monitor["spec errors against the live types"] = "; ".join(e.splitlines()[0] for e in self.livecheck.errors) \
            or "none"
        if self.error_guard.active:
            monitor["data error actions"] = "running " + ", ".join(self.error_guard.actions)
        assert self.spec is not None
        entries = status_mod.build(self.spec, rules, active, topics, nodes, field_errors, monitor, failing, computed)
        self.outputs.status(entries, _ros_now())

    def shutdown(self) -> None:
        """Release non-latched actions, close ports and publishers."""
        if self._stopping:
            return
        loop = self.loop
        if loop is None:  # not enforcing: nothing to release
            rospy.loginfo("rubass: stopping (nothing was enforced)")
            self._stopping = True
            self.master_watch.stop()
            return
        now = _ros_now()

        def release(engine: Engine) -> None:
            keys = self.dispatcher.keys_of(engine.spec)
            for index in engine.active_behaviours():
                b = engine.spec.behaviours[index - 1]
                if not b.latched:
                    self.dispatcher.release(b, keys[index], now)
                    self.dispatcher.report_event(Event(now, "release", index), b, (), "shutdown")  # pairs its start
            if not any(engine.spec.actions[a].latch for a in self.overload.actions):
                self.overload.release(now, self.dispatcher.runners, "the monitor stops")
            if not any(engine.spec.actions[a].latch for a in self.error_guard.actions):
                self.error_guard.release(now, self.dispatcher.runners, "the monitor stops")

        rospy.loginfo("rubass: stopping: releasing non-latched actions")
        try:
            loop.call(release, timeout=1.0)
        except Exception as exc:  # the engine thread is stuck: stop anyway
            rospy.logerr(f"rubass: could not release actions at shutdown: {exc}")
        self._stopping = True
        self.master_watch.stop()
        loop.stop()
        self.sampler.stop()
        self.livecheck.close()
        received = sum(st.messages for st in self.watcher.status())
        rospy.loginfo("rubass: stopped after %s (%d dropped because the engine's queue was full), %s",
                      counted(received, "message"), loop.dropped, counted(self.reloads, "reload"))  # bench/ reads it
        # the releases are handed to the actions' threads; what follows unregisters from rospy, which
        # may wait for good for a master that does not answer (a registration holds its lock)
        exit_within(EXIT_GRACE + 1.0 * len(self.runners))
        self.watcher.close()
        for runner in self.runners.values():
            runner.stop(timeout=1.0)
            runner.plugin.close()
