"""What a reload replaces is freed at once, by reference counting: a checked spec and its engine
hold no reference cycles, so they do not wait for the cyclic garbage collector (a storm of
SIGHUPs grew the monitor by 4-6 MB that way), and reading a file does not allocate its limit."""
import gc
import glob
import os
import tracemalloc
import weakref

import pytest

from rubass.engine import Engine
from rubass.lang import load_spec
from rubass.lang.sourcefile import MAX_BYTES, read_at_most, read_source

from conftest import ROOT

SPECS = sorted(glob.glob(os.path.join(ROOT, "config", "*.rbs")))


@pytest.fixture
def no_cyclic_gc():
    gc.collect()
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def test_the_configs_are_there():
    assert len(SPECS) >= 5


def run(path):
    libs = [lib for lib in [path.replace(".rbs", "_actions.yaml")] if os.path.exists(lib)]
    spec = load_spec(path, libs)
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    for topic in spec.topics:
        engine.on_message(topic, 0.5, None)  # a topic whose message cannot be read: unknown values
    engine.advance(5.0)
    return spec, engine


@pytest.mark.parametrize("path", SPECS, ids=os.path.basename)
def test_a_replaced_spec_and_engine_are_freed_without_the_cyclic_collector(path, no_cyclic_gc):
    run(path)  # the first run's one-time set-up (imports, the grammar) may leave garbage
    gc.collect()
    spec, engine = run(path)
    gone = [weakref.ref(spec), weakref.ref(engine), weakref.ref(spec.spec)]
    del spec, engine
    assert [r() for r in gone] == [None, None, None], "freed when the last reference went"
    # counted in a fresh interpreter: the test process runs other threads (rospy's, from earlier
    # tests that started a node in-process) whose own garbage a collection here would count too
    assert garbage_of_a_second_run(path) == 0, "loading, checking and running a spec again leaves no cyclic garbage"


def refused(path):
    """Load a spec that has errors (SpecError), as a reload that is rejected does."""
    from rubass.lang import SpecError
    try:
        load_spec(path)
    except SpecError:
        pass


def garbage_of_a_second_run(path, how="run"):
    """gc.collect() after `how`(path) twice in a new interpreter, the collector off meanwhile."""
    import subprocess
    import sys

    code = ("import gc, sys; gc.disable(); sys.path[:0] = sys.argv[3:]; import test_reload_garbage as t; "
            "f = getattr(t, sys.argv[2]); f(sys.argv[1]); gc.collect(); f(sys.argv[1]); print(gc.collect())")
    here = os.path.dirname(os.path.abspath(__file__))
    out = subprocess.run([sys.executable, "-c", code, path, how, ROOT, os.path.dirname(here), here],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return int(out.stdout.split()[-1])


def test_a_spec_with_errors_leaves_no_cyclic_garbage_either(tmp_path, no_cyclic_gc):
    from rubass.lang import SpecError

    lib = tmp_path / "lib.yaml"
    lib.write_text("actions:\n  brake: {plugin: publish, topic: /brake, type: std_msgs/Bool, message: {data: true}}\n")
    bad = tmp_path / "bad.rbs"
    bad.write_text('import "lib.yaml";\naction primitive brake;\nentity a { rules: r: a.q; q: a.r; }\n'
                   "if (a.r) then { brake; }\n")
    with pytest.raises(SpecError) as exc:
        load_spec(str(bad))
    assert "cyclic rule reference" in exc.value.render()
    assert garbage_of_a_second_run(str(bad), "refused") == 0  # in a fresh interpreter, as above


def test_reading_a_small_spec_does_not_allocate_the_4_mib_limit(tmp_path):
    path = tmp_path / "s.rbs"
    path.write_text("// a comment\n" * 10)
    tracemalloc.start()
    try:
        src, diag = read_source(str(path))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert diag is None and src.text.count("\n") == 10
    assert peak < 64 * 1024, f"{peak} bytes allocated to read 130 bytes"


def test_read_at_most_reads_a_file_whose_size_the_kernel_does_not_report():
    with open("/proc/self/status", "rb") as fh:  # a regular file of size 0 with content
        assert os.fstat(fh.fileno()).st_size == 0
        data = read_at_most(fh, MAX_BYTES + 1)
    assert data.startswith(b"Name:") and data.endswith(b"\n")


def test_read_at_most_stops_at_the_limit_and_a_file_over_it_is_refused(tmp_path):
    path = tmp_path / "big.rbs"
    path.write_bytes(b"x" * 1000)
    with open(path, "rb") as fh:
        assert len(read_at_most(fh, 100)) == 100
    with open(path, "rb") as fh:
        assert read_at_most(fh, 5000) == b"x" * 1000
    path.write_bytes(b"/" * (MAX_BYTES + 1))
    src, diag = read_source(str(path))
    assert src is None and "over the limit of 4194304 bytes" in diag.message


def test_read_at_most_reads_on_when_the_file_grows_while_it_is_read(tmp_path):
    path = tmp_path / "growing.rbs"
    path.write_bytes(b"a" * 10)
    with open(path, "rb") as fh, open(path, "ab") as writer:
        real = os.fstat
        def stale_fstat(fd):  # noqa: E306 - the size seen before a writer appended
            st = real(fd)
            writer.write(b"b" * 70_000)
            writer.flush()
            return st
        os.fstat, saved = stale_fstat, os.fstat
        try:
            data = read_at_most(fh, 1 << 20)
        finally:
            os.fstat = saved
    assert data == b"a" * 10 + b"b" * 70_000
