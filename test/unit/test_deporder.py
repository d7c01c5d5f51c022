"""dependency_order: the order in which the checker puts rules and behaviours (§14), and the
cycles it reports."""
from hypothesis import given, settings
from hypothesis import strategies as st

from rubass.lang.deporder import dependency_order


def order(graph, roots=None):
    cycles = []
    out = dependency_order(roots if roots is not None else list(graph), lambda n: graph.get(n, ()), cycles.append)
    return out, cycles


def test_each_node_comes_after_what_it_depends_on_in_the_order_given():
    assert order({"a": ["b", "c"], "b": ["c"], "c": [], "d": []}) == (["c", "b", "a", "d"], [])


def test_a_cycle_is_reported_once_from_where_it_closes_and_every_node_still_comes_out_once():
    out, cycles = order({"a": ["b"], "b": ["c"], "c": ["b"]})
    assert out == ["c", "b", "a"] and cycles == [["b", "c", "b"]]
    assert order({"a": ["a"]}) == (["a"], [["a", "a"]])


def test_a_chain_of_100000_rules_needs_no_recursion():
    graph = {f"r{i}": [f"r{i + 1}"] for i in range(100_000)}
    out, cycles = order(graph, ["r0"])
    assert out[0] == "r100000" and out[-1] == "r0" and len(out) == 100_001 and cycles == []


graphs = st.integers(1, 12).flatmap(lambda n: st.lists(
    st.lists(st.integers(0, n - 1), max_size=4), min_size=n, max_size=n).map(
    lambda edges: {f"n{i}": [f"n{j}" for j in e] for i, e in enumerate(edges)}))


def reference(graph):
    """The recursive depth-first search it replaced (rubass 2.0), as the oracle."""
    done, state, path, at, cycles = [], {}, [], {}, []

    def visit(node):
        if state.get(node) == 2:
            return
        if state.get(node) == 1:
            cycles.append(path[at[node]:] + [node])
            return
        state[node], at[node] = 1, len(path)
        path.append(node)
        for dep in graph.get(node, ()):
            visit(dep)
        path.pop()
        state[node] = 2
        done.append(node)

    for node in graph:
        visit(node)
    return done, cycles


@settings(max_examples=300, deadline=None)
@given(graphs)
def test_it_gives_the_same_order_and_cycles_as_the_recursive_search(graph):
    out, cycles = order(graph)
    assert (out, cycles) == reference(graph)
    assert sorted(out) == sorted(graph)
    if not cycles:  # a topological order
        seen = set()
        for node in out:
            assert all(dep in seen for dep in graph[node])
            seen.add(node)
