"""Fuzzing the whole front end, files and YAML action libraries included (issue #7).

One property, `clean_errors_only`: a spec and its library, written to disk as a user would,
checked by `rubass check` in-process. It exits 0 or 1, never raises, prints no traceback,
and every error it prints is `file:line:col: error: …` (or `file: error: …` for a file that
cannot be read). The strategies mutate the project's own specs and libraries, so most cases
are nearly valid and reach deep into the checker, not just the first token.

Used by test/unit/test_fuzz.py (a few hundred cases) and bench/fuzz.py (thousands).
"""
import contextlib
import glob
import io
import os
import re

from hypothesis import strategies as st

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _read(pattern):
    return [open(p, encoding="utf-8").read() for p in sorted(glob.glob(os.path.join(ROOT, pattern)))]


SPECS = [re.sub(r'import "[^"]*";', 'import "lib.yaml";', t) if "import" in t else 'import "lib.yaml";\n' + t
         for t in _read("config/*.rbs")]
LIBRARIES = _read("config/*_actions.yaml") + _read("docs/examples/*.yaml")
SPEC_TOKENS = ["(", ")", "{", "}", ";", ":", ",", ".", "for", "and", "or", "not", "topic", "node", "if", "then",
               "entity", "rules", "const", "import", "action", "primitive", "1", "0.4 s", "m/s", "%", '"', "//",
               "/*", "*/", "<", "==", "-", "/x", "age(", "frequency(", "alive(", "cpu(", "base", "\n", "[", "]",
               "[-1]", "\\", "1e999", "nan", "import \"lib.yaml\";", "import \"package://nope/x.yaml\";",
               "import \"/etc/shadow\";", "import \"/dev/zero\";", "action primitive stop;"]
YAML_TOKENS = [": ", "- ", "{", "}", "[", "]", ",", "\n", "  ", "\t", "'", '"', "#", "&a ", "*a", "<<: *a",
               "!!python/object/apply:os.system ['touch /tmp/rubass-pwned']", "!!python/name:os.system ", "!custom ",
               "!!binary AAAA", "? ", "---\n",
               "...\n", "%YAML 1.1\n", "null", "~", "1e999", "-1 Hz", "0 Hz", "plugin: ", "serial", "publish",
               "service", "log", "custom.mod:Cls", "rate: ", "port: ", "type: ", "std_msgs/Nope", "message: ",
               "latch: ", "yes", "on_start: ", "\x00", "\ufeff", "é"]


def _mutate(draw, text, tokens):
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(text)))
        kind = draw(st.sampled_from(["delete", "insert", "token", "dup", "swap"]))
        if kind == "delete":
            text = text[:pos] + text[pos + draw(st.integers(1, 40)):]
        elif kind == "insert":
            text = text[:pos] + draw(st.text(max_size=6)) + text[pos:]
        elif kind == "token":
            text = text[:pos] + draw(st.sampled_from(tokens)) + text[pos:]
        elif kind == "dup":
            end = min(len(text), pos + draw(st.integers(1, 80)))
            text = text[:end] + text[pos:end] + text[end:]
        else:
            lines = text.split("\n")
            i, j = draw(st.integers(0, len(lines) - 1)), draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
    return text


@st.composite
def spec_and_library(draw):
    """(spec text, library text), at least one of them mutated."""
    spec, lib = draw(st.sampled_from(SPECS)), draw(st.sampled_from(LIBRARIES))
    which = draw(st.sampled_from(["spec", "library", "both"]))
    if which != "library":
        spec = _mutate(draw, spec, SPEC_TOKENS)
    if which != "spec":
        lib = _mutate(draw, lib, YAML_TOKENS)
    return spec, lib


DIAG = re.compile(r"^(\S.*?):(\d+):(\d+): (error|warning): \S|^\S.*?: (error|warning): \S")


def clean_errors_only(directory, spec_text, lib_text):
    """Write both files, run `rubass check`; assert it fails, if at all, only cleanly."""
    from rubass.cli import main

    spec_path, lib_path = os.path.join(directory, "s.rbs"), os.path.join(directory, "lib.yaml")
    with open(spec_path, "w", encoding="utf-8", errors="surrogatepass") as fh:
        fh.write(spec_text)
    with open(lib_path, "w", encoding="utf-8", errors="surrogatepass") as fh:
        fh.write(lib_text)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["check", spec_path])  # an exception here fails the property: a traceback
    text = err.getvalue()
    assert status in (0, 1), (status, text)
    assert "Traceback" not in text
    if status == 1:
        first = text.splitlines()[0]
        assert DIAG.match(first), first
    assert not os.path.exists("/tmp/rubass-pwned"), "a YAML tag ran a command"
    return status
