"""The rows of the paper's Table 1: what each experiment injects, where its timing starts,
the ideal reaction of its rules, and the paper's own figures (seconds)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple

MONITOR_NICE = -10  # the monitor's ~nice in every run, as docs/monitor.md advises on a busy robot computer

@dataclass(frozen=True)
class Row:
    name: str
    robot: str                      # 'kobuki' or 'frobit'
    spec: str                       # file in config/
    fault: Dict[str, Any] = field(hash=False)
    origin: str                     # event the paper's timing (a) starts from
    ideal: float
    paper: Optional[Tuple[float, float, float, float]]  # Avg, SD, Min, Max; None: not a row of the paper
    note: str = ""
    until: str = "stop_received"   # event that ends the reaction (a) and the wait
    world: bool = False            # with the obstacle, laser and bumper (rubass_experiments.world)
    behaviour: str = ""            # the behaviour whose start (b) is measured from; "": the first


def _wheels(left: Dict[str, bool], right: Dict[str, bool]) -> Dict[str, Any]:
    return {"wheels": {"left": left, "right": right}}


E, M = {"encoder_dead": True}, {"motor_full": True}
ROWS: List[Row] = [
    Row("E_B", "frobit", "frobit.rbs", _wheels(E, E), "fault_applied", 1.40, (2.07, 0.35, 1.41, 2.66)),
    Row("E_L", "frobit", "frobit.rbs", _wheels(E, {}), "fault_applied", 1.40, (1.87, 0.24, 1.60, 2.34)),
    Row("M_B", "frobit", "frobit.rbs", _wheels(M, M), "fault_applied", 0.50, (0.82, 0.13, 0.61, 1.02)),
    Row("M_L", "frobit", "frobit.rbs", _wheels(M, {}), "fault_applied", 0.50, (1.71, 0.30, 0.92, 2.13)),
    Row("M_R", "frobit", "frobit.rbs", _wheels({}, M), "fault_applied", 0.50, (0.86, 0.31, 0.58, 1.56),
        note="the paper's row 'M_LR', read as the right motor"),
    Row("M_L+E_R", "frobit", "frobit.rbs", _wheels(M, E), "fault_applied", 0.50, (0.72, 0.10, 0.58, 0.93)),
    Row("M_R+E_L", "frobit", "frobit.rbs", _wheels(E, M), "fault_applied", 0.50, (0.74, 0.18, 0.57, 1.11)),
    Row("Boundary", "kobuki", "kobuki.rbs", {"goal": [4.0, 0.0]}, "boundary", 0.00, (0.07, 0.02, 0.03, 0.09)),
    Row("Max speed", "kobuki", "kobuki.rbs", {"drift": "linear", "rate": 0.5}, "limit_exceeded", 1.00,
        (1.23, 0.42, 0.91, 2.00)),
    Row("Max spin", "kobuki", "kobuki.rbs", {"drift": "angular", "rate": 2.0}, "limit_exceeded", 0.70,
        (8.15, 1.89, 4.66, 10.32)),
    Row("Spin (0.2 s)", "kobuki", "kobuki_spin_0.2s.rbs", {"drift": "angular", "rate": 2.0}, "limit_exceeded", 0.20,
        (0.17, 0.03, 0.12, 0.21)),
    Row("Spin (0 s)", "kobuki", "kobuki_spin_0s.rbs", {"drift": "angular", "rate": 2.0}, "limit_exceeded", 0.00,
        (0.17, 0.04, 0.11, 0.22)),
    Row("CPU", "kobuki", "kobuki.rbs", {"cpu_hog": 8.0, "threads": 2}, "cpu_hog_start", 1.50, (1.71, 0.14, 1.51, 1.95),
        note="(a) includes the node sampling period (10 Hz) and any CPU the loop is denied"),
    # Beyond the paper: speed limits rather than stops (LANGUAGE.md §16, config/kobuki_creep.rbs)
    Row("Creep", "kobuki", "kobuki_creep.rbs", {"goal": [1.5, -1.0]}, "obstacle_near", 0.00, None,
        note="not in the paper: from the scan that first shows the obstacle within 0.8 m to the command clamped "
             "to 0.1 m/s reaching the base", until="creep_received", world=True, behaviour="creep"),
    Row("Back away", "kobuki", "kobuki_creep.rbs", {"goal": [1.5, -1.0]}, "bumper_pressed", 0.00, None,
        note="not in the paper: from the bumper's contact to the first command that neither advances nor turns, "
             "over the creep", until="escape_received", world=True, behaviour="escape"),
    Row("Zone stop", "kobuki", "kobuki_creep.rbs", {"goal": [4.0, 0.0]}, "boundary", 0.00, None,
        note="not in the paper: the zone's polygon border, the stop outranking the limits", world=True,
        behaviour="zone_stop"),
]


def row(name: str) -> Row:
    for r in ROWS:
        if r.name.lower() == name.lower():
            return r
    raise KeyError(name)


@dataclass(frozen=True)
class Stats:
    n: int
    avg: float
    sd: float
    min: float
    max: float
    p99: float


def stats(values: Sequence[float]) -> Optional[Stats]:
    """Avg, sample SD, Min, Max and p99 (nearest rank) of the values; None when there are none."""
    v = sorted(values)
    if not v:
        return None
    n = len(v)
    avg = sum(v) / n
    sd = math.sqrt(sum((x - avg) ** 2 for x in v) / (n - 1)) if n > 1 else 0.0
    p99 = v[max(0, min(n - 1, math.ceil(0.99 * n) - 1))]
    return Stats(n, avg, sd, v[0], v[-1], p99)
