"""The experiment runner: every row of the paper's Table 1 on the simulated robots, N times.

Each run starts its own processes (base, driver, fault injector, the monitor, rosbag record)
on the runner's master, lets the robot drive, injects the fault, and waits for the stop to
reach the base. Every process is the Supervisor's (procs.py): a stop signal (SIGINT, SIGTERM,
SIGHUP) ends the run in progress cleanly (its bag closed) and keeps the finished runs; the
processes die with the runner even when it is SIGKILLed. The nodes log wall-clock events to one
file per run, from which:
(a) the paper's time: from the row's origin (the fault, the first command over the limit,
    the crossing of the border, the start of the CPU loop) to the stop reaching the base;
(b) the monitor's own delay: from the instant its rule became due, computed afterwards by
    replaying the run's bag through the same engine, to the stop reaching the base.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from rubass.lang import SpecError, load_spec
from rubass.replay.run import replay
from .rows import MONITOR_NICE, Row
from rubass.ros.bag import BagError, open_bag, read
from .master import ROOT, PrivateMaster, wait_for_service
from .eventlog import read_events
from .procs import Interrupted, Supervisor

PY = "/usr/bin/python3"
CONFIG = os.path.join(ROOT, "config")
WARMUP = 1.5        # seconds of normal driving before the fault
STOP_TIMEOUT = 25.0  # seconds after the fault to wait for the stop


@dataclass
class RunResult:
    row: str
    rep: int
    stopped: bool
    a: Optional[float] = None        # seconds, the paper's definition
    b: Optional[float] = None        # seconds, the monitor's own delay
    b_monitor: Optional[float] = None  # of (b): due instant -> the monitor dispatching the stop (its ~events start)
    nice_refused: bool = False       # the monitor could not take MONITOR_NICE (not root): it ran as started
    due_source: str = ""
    error: str = ""
    bag: str = ""
    interrupted: bool = False        # a stop signal ended this run; it counts in no figure
    events: List[Dict[str, Any]] = field(default_factory=list)


@dataclass
class Outcome:
    """What main_loop ran: the finished runs, and if a stop signal ended it, which one and the
    run it cut short (its bag closed, its folder kept)."""
    results: List[RunResult]
    signal: Optional[int] = None
    cut_short: Optional[RunResult] = None


class Session:
    """A private rosmaster for the whole experiment, and this process as a ROS node."""

    def __init__(self, out: str, sup: Supervisor) -> None:
        self.out = out
        self.sup = sup
        with sup.deferred():  # the master is the supervisor's from its first instant
            self.master = PrivateMaster(os.path.join(out, "ros_home"))
            sup.adopt(self.master.process)
        self.env = self.master.env
        self.master.join()
        import rospy
        from std_msgs.msg import String

        rospy.init_node("rubass_experiments", disable_signals=True)
        self.faults = rospy.Publisher("/sim/fault", String, queue_size=10, tcp_nodelay=True)

    def close(self) -> None:
        import rospy

        with self.sup.deferred(raise_after=False):
            rospy.signal_shutdown("experiments done")
            self.sup.stop_all()


def _spec_for(row: Row, run_dir: str) -> str:
    """The spec the monitor runs: config/ as it is, but the Frobit board on this run's pty."""
    if row.robot != "frobit":
        return os.path.join(CONFIG, row.spec)
    shutil.copy(os.path.join(CONFIG, row.spec), run_dir)
    with open(os.path.join(CONFIG, "frobit_actions.yaml")) as fh:
        lib = fh.read().replace("/dev/ttyACM0", os.path.join(run_dir, "board"))
    with open(os.path.join(run_dir, "frobit_actions.yaml"), "w") as fh:
        fh.write(lib)
    return os.path.join(run_dir, row.spec)


def spec_problems(rows: List[Row]) -> List[str]:
    """Each row whose spec in config/ (or an action library it imports) is missing or does not check, with
    the checker's errors: found before any run (a missing one broke the runs with a traceback, or read as a
    missed stop)."""
    problems: List[str] = []
    checked: Dict[str, str] = {}
    for r in rows:
        if r.spec not in checked:
            try:
                load_spec(os.path.join(CONFIG, r.spec))
                checked[r.spec] = ""
            except SpecError as exc:
                checked[r.spec] = exc.render()
        if checked[r.spec]:  # its action library too: the spec imports it
            problems.append(f"row {r.name}: config/{r.spec} cannot be used:\n{checked[r.spec]}")
    return problems


def _bag_topics(row: Row) -> List[str]:
    if row.robot == "kobuki":
        return ["/mobile_base/commands/velocity", "/odom", "/cmd_vel", "/mobile_base/commands/safety_velocity",
                "/rubass/events", "/rubass/node_samples", "/sim/fault"] + \
            (["/scan", "/mobile_base/sensors/bumper"] if row.world else [])
    return ["/wheel_left/cmd", "/wheel_right/cmd", "/wheel_left/encoder", "/wheel_right/encoder", "/odom",
            "/wheel_left/safety_cmd", "/wheel_right/safety_cmd", "/rubass/events", "/sim/fault"]


def _recorder(bag: str, topics: List[str]) -> Tuple[List[str], int]:
    """rosbag's `record` program itself (the `rosbag record` wrapper exits before it, so it
    could not be waited for): the command line, and SIGINT, which closes the bag cleanly."""
    try:
        from roslib.packages import find_node

        found = find_node("rosbag", "record")
    except Exception:  # noqa: BLE001 - any failure: the wrapper
        found = []
    program = found[:1] if found else ["rosbag", "record"]
    return program + ["--tcpnodelay", "-O", bag] + topics, signal.SIGINT


def run_once(session: Session, row: Row, rep: int) -> RunResult:
    """One run of a row; a stop signal ends it early (result.interrupted) with every process
    stopped and the bag closed."""
    run_dir = os.path.join(session.out, "runs", row.name.replace(" ", "_").replace("(", "").replace(")", ""), str(rep))
    shutil.rmtree(run_dir, ignore_errors=True)
    os.makedirs(run_dir)
    events_file = os.path.join(run_dir, "events.jsonl")
    spec_path = _spec_for(row, run_dir)
    procs: List[subprocess.Popen] = []

    def spawn(name: str, args: List[str], stop_signal: int = signal.SIGTERM) -> subprocess.Popen:
        with open(os.path.join(run_dir, f"{name}.log"), "w") as log:
            p = session.sup.spawn(args, env=session.env, stdout=log, cwd=run_dir, stop_signal=stop_signal)
        procs.append(p)
        return p

    ev = f"_events_file:={events_file}"
    if row.robot == "kobuki":
        spawn("base", [PY, "-m", "rubass_experiments.kobuki", "__name:=mobile_base", ev])
        if row.world:
            spawn("world", [PY, "-m", "rubass_experiments.world", "__name:=world", ev])
        spawn("injector", [PY, "-m", "rubass_experiments.injector", "__name:=fault_injector", ev])
        spawn("driver", [PY, "-m", "rubass_experiments.driver", "__name:=controller", "_robot:=kobuki", ev,
                         "_goal_x:=2.5", "_goal_y:=1.0"])
    else:
        spawn("base", [PY, "-m", "rubass_experiments.frobit", "__name:=frobit_base", ev,
                       f"_board_port:={os.path.join(run_dir, 'board')}", f"_seed:={rep}"])
        spawn("driver", [PY, "-m", "rubass_experiments.driver", "__name:=controller", "_robot:=frobit", ev,
                         "_goal_x:=4.0", "_goal_y:=1.0"])
    bag = os.path.join(run_dir, "run.bag")
    recorder = spawn("rosbag", *_recorder(bag, _bag_topics(row)))
    result = RunResult(row.name, rep, False, bag=bag)

    def close_bag() -> None:
        session.sup.stop([recorder])
        # with the `rosbag record` wrapper, its child renames run.bag.active after the wrapper exits
        _wait(lambda: not os.path.exists(bag + ".active"), 15, "the bag")

    try:
        if row.robot == "frobit":
            _wait(lambda: os.path.lexists(os.path.join(run_dir, "board")), 15, "the safety board's port")
        monitor = spawn("monitor", [PY, os.path.join(ROOT, "scripts", "monitor"), "__name:=rubass",
                                    f"_spec:={spec_path}", "_node_rate:=10", f"_nice:={MONITOR_NICE}",
                                    # each run starts unlatched: its own latch state file (issue 13)
                                    f"_state_file:={os.path.join(run_dir, 'latches.json')}"])
        wait_for_service("/rubass/reset", monitor, session.master.uri, 30)
        expected = 3 if row.robot == "kobuki" else 2  # the nodes that listen to /sim/fault
        _wait(lambda: session.faults.get_num_connections() >= expected, 15, "the simulated nodes")
        time.sleep(WARMUP)
        if any(e["event"] == "stop_received" for e in read_events(events_file)):
            result.error = "stopped before the fault (a false positive)"
            return result
        session.faults.publish(json.dumps(row.fault))
        fault_sent = time.time()
        end = fault_sent + STOP_TIMEOUT
        while time.time() < end and not any(e["event"] == row.until for e in read_events(events_file)):
            time.sleep(0.01)
        time.sleep(0.3)  # let the recorder catch the last messages
        close_bag()
        _wait(lambda: os.path.exists(bag), 1, "the bag")
        result.events = read_events(events_file)
        _measure(row, result, spec_path, fault_sent)
        with open(os.path.join(run_dir, "monitor.log"), errors="replace") as fh:
            result.nice_refused = f"~nice {MONITOR_NICE}: " in fh.read()
    except Interrupted as exc:
        result.interrupted, result.error = True, f"interrupted by {exc.name}"
    except Exception as exc:  # a run that breaks is reported, and the others go on
        result.error = f"{exc.__class__.__name__}: {exc}"
    finally:
        session.sup.stop([p for p in reversed(procs) if p is not recorder])
        try:
            with session.sup.deferred(raise_after=False):
                close_bag()
        except RuntimeError as exc:
            result.error = result.error or str(exc)
    return result


def _wait(cond: Any, timeout: float, what: str) -> None:
    end = time.time() + timeout
    while not cond():
        if time.time() > end:
            raise RuntimeError(f"{what} did not come up within {timeout:g} s")
        time.sleep(0.02)


def _first(events: List[Dict[str, Any]], name: str, after: float = 0.0) -> Optional[float]:
    times = [e["wall"] for e in events if e["event"] == name and e["wall"] >= after]
    return min(times) if times else None


def _measure(row: Row, result: RunResult, spec_path: str, fault_sent: float) -> None:
    stop = _first(result.events, row.until)
    if stop is None:
        result.error = f"no {row.until.replace('_', ' ')} within {STOP_TIMEOUT:g} s of the fault"
        return
    result.stopped = True
    origin = _first(result.events, row.origin, fault_sent - 1.0)
    if origin is None:
        result.error = f"no '{row.origin}' event"
        return
    result.a = stop - origin
    due = _due_from_bag(spec_path, result.bag, fault_sent, row.behaviour)
    result.due_source = "replay of the run's bag (with the monitor's node samples)"
    if due is None:
        result.error = "the replay of the bag found no behaviour start"
        return
    result.b = stop - due  # negative when the recorder got the data after the base got the stop (table.py says so)
    dispatched = _dispatch_from_bag(result.bag, fault_sent, row.behaviour)
    if dispatched is not None:  # the rest of (b) is the stop's way to the base: a hop, the base's own pauses
        result.b_monitor = dispatched - due


def _due_from_bag(spec_path: str, bag_path: str, after: float, behaviour: str = "") -> Optional[float]:
    """The first start after `after` (of that behaviour, if named), as the engine computes it
    from the recording."""
    spec = load_spec(spec_path)
    try:
        bag, info = open_bag(bag_path)
    except BagError:
        return None
    with bag:
        topics = [t for t in spec.topics if t in info.types]
        nodes = ["/rubass/node_samples"] if "/rubass/node_samples" in info.types else []
        decode = {t for t in topics if spec.topics[t].needs_data} | set(nodes)
        _, events = replay(spec, read(bag, topics + nodes, decode), info.start, info.end, node_topics=nodes)
    wanted = spec.behaviour(behaviour).index if behaviour else None
    starts = [info.start + e.time for e in events if e.kind == "start" and info.start + e.time >= after - 0.5
              and wanted in (None, e.behaviour)]
    return min(starts) if starts else None


def _dispatch_from_bag(bag_path: str, after: float, behaviour: str = "") -> Optional[float]:
    """When the monitor dispatched the first start after `after` (of that behaviour, if named), as
    its ~events record says: the instant it became due by its own clock plus its latency."""
    try:
        bag, info = open_bag(bag_path)
    except BagError:
        return None
    with bag:
        if "/rubass/events" not in info.types:
            return None
        for _, _, msg in read(bag, ["/rubass/events"], {"/rubass/events"}):
            try:
                record = json.loads(msg.data)
            except (AttributeError, ValueError):
                continue
            if (record.get("event") == "start" and record.get("time", 0.0) >= after - 0.5
                    and record.get("latency_ms") is not None and (not behaviour or record.get("name") == behaviour)):
                return record["time"] + record["latency_ms"] / 1000.0
    return None


def results_json(rows: List[Row], results: List[RunResult]) -> Dict[str, Any]:
    from .rows import stats

    out: Dict[str, Any] = {"rows": []}
    for r in rows:
        runs = [x for x in results if x.row == r.name]
        sa = stats([x.a for x in runs if x.a is not None])
        sb = stats([x.b for x in runs if x.b is not None])
        out["rows"].append({
            "row": r.name, "robot": r.robot, "spec": r.spec, "ideal": r.ideal, "note": r.note,
            "paper": dict(zip(("avg", "sd", "min", "max"), r.paper)) if r.paper else None,
            "a": asdict(sa) if sa else None, "b": asdict(sb) if sb else None,
            "runs": len(runs), "stopped": sum(x.stopped for x in runs),
            "errors": [x.error for x in runs if x.error],
            "details": [{k: v for k, v in asdict(x).items() if k != "events"} for x in runs],
        })
    return out


def main_loop(rows: List[Row], reps: int, out: str, sup: Supervisor, progress: Any = sys.stderr) -> Outcome:
    """Every run of every row, until done or a stop signal; every process is stopped on return."""
    os.makedirs(out, exist_ok=True)
    outcome = Outcome([])
    session: Optional[Session] = None
    try:
        session = Session(out, sup)
        for r in rows:
            for rep in range(reps):
                res = run_once(session, r, rep)
                if res.interrupted:
                    outcome.cut_short = res
                    progress.write(f"  {r.name:<13} run {rep + 1}/{reps}: {res.error}; its bag: {res.bag}\n")
                    return outcome
                outcome.results.append(res)
                a = f"{res.a:.3f} s" if res.a is not None else "-"
                b = f"{res.b * 1000:.1f} ms" if res.b is not None else "-"
                if res.b is not None and res.b_monitor is not None:
                    b += f" ({res.b_monitor * 1000:.1f} in the monitor, {(res.b - res.b_monitor) * 1000:.1f} to the base)"
                progress.write(f"  {r.name:<13} run {rep + 1}/{reps}: stopped={res.stopped} (a) {a} (b) {b}"
                               f"{'  ' + res.error if res.error else ''}\n")
                progress.flush()
                sup.check()  # a signal during the run's own cleanup ends the loop here
    except Interrupted:
        pass
    finally:
        if session is not None:
            session.close()
        sup.stop_all()
        outcome.signal = sup.signum
    return outcome
