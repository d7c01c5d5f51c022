"""Dependency order: every node after the nodes it depends on, with the cycles found on the way."""
from __future__ import annotations

from typing import Callable, Dict, Iterable, Iterator, List, Tuple


def dependency_order(roots: Iterable[str], deps: Callable[[str], Iterable[str]],
                     on_cycle: Callable[[List[str]], None]) -> List[str]:
    """The nodes reachable from `roots`, depth first in the order given, each after its
    dependencies. on_cycle(cycle) is called for each back edge; `cycle` starts and ends with the
    same node. Iterative: no recursion limit for long chains of rules, and no self-referring
    closure, which would keep the whole checked spec alive until the cyclic garbage collector
    runs."""
    done: List[str] = []
    state: Dict[str, int] = {}  # 1: on the current path, 2: done
    path: List[str] = []  # the nodes being visited, outermost first
    at: Dict[str, int] = {}  # node -> its index in path
    for root in roots:
        if state.get(root) == 2:
            continue
        stack: List[Tuple[str, Iterator[str]]] = [(root, iter(deps(root)))]
        state[root], at[root] = 1, 0
        path.append(root)
        while stack:
            node, todo = stack[-1]
            for dep in todo:
                seen = state.get(dep)
                if seen == 2:
                    continue
                if seen == 1:
                    on_cycle(path[at[dep]:] + [dep])
                    continue
                state[dep], at[dep] = 1, len(path)
                path.append(dep)
                stack.append((dep, iter(deps(dep))))
                break
            else:
                stack.pop()
                path.pop()
                state[node] = 2
                done.append(node)
    return done
