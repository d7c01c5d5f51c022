"""Every example in LANGUAGE.md, docs/ and config/ parses and checks."""
import glob
import os
import re

import pytest

from rubass.lang import check_text, load_spec

from conftest import ROOT, shared_path

EXAMPLE_LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def code_blocks(path):
    """The ``` blocks of a Markdown file that hold RuBaSS (not YAML, shell or EBNF)."""
    text = open(path, encoding="utf-8").read()
    blocks = re.findall(r"```([a-z]*)\n(.*?)```", text, re.S)
    return [b for lang, b in blocks if lang in ("", "rubass") and not b.lstrip().startswith(("actions:", "$", "rubass "))
            and ("entity" in b or "const" in b or "if (" in b or "action" in b)]


def test_language_md_first_example_checks():
    path = shared_path("spec", "LANGUAGE.md")
    blocks = code_blocks(path)
    assert blocks, "no RuBaSS example found in LANGUAGE.md"
    fig2 = open(os.path.join(ROOT, "config", "fig2.rbs"), encoding="utf-8").read()
    assert blocks[0] == fig2, "config/fig2.rbs must be LANGUAGE.md §1 exactly as printed"
    for b in blocks:
        check_text(b, os.path.join(ROOT, "docs", "examples", "example.rbs"), [EXAMPLE_LIB])


def test_language_md_yaml_library_validates(tmp_path):
    text = open(shared_path("spec", "LANGUAGE.md"), encoding="utf-8").read()
    yaml_block = re.search(r"```yaml\n(.*?)```", text, re.S).group(1)
    lib = tmp_path / "lib.yaml"
    lib.write_text(yaml_block)
    spec = check_text("action primitive stop, board_stop, warn;\nif (true) then { stop; board_stop; warn; }\n",
                      str(tmp_path / "s.rbs"), [str(lib)])
    assert spec.actions["stop"].latch and spec.actions["stop"].params["rate"] == 20.0
    assert spec.actions["board_stop"].params["on_start"] == "S\n"


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))))
def test_docs_examples_check(path):
    for block in code_blocks(path):
        if "// error" in block:  # examples of errors must fail to check
            continue
        check_text(block, os.path.join(ROOT, "docs", "examples", "example.rbs"), [EXAMPLE_LIB])


def test_docs_error_examples_fail():
    from rubass.lang import SpecError

    found = 0
    for path in glob.glob(os.path.join(ROOT, "docs", "*.md")):
        for block in code_blocks(path):
            if "// error" in block:
                found += 1
                with pytest.raises(SpecError):
                    check_text(block, os.path.join(ROOT, "docs", "examples", "example.rbs"), [EXAMPLE_LIB])
    assert found


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(ROOT, "config", "*.rbs"))))
def test_config_specs_check(path):
    extra = [os.path.join(ROOT, "config", "fig2_actions.yaml")] if path.endswith("fig2.rbs") else []
    spec = load_spec(path, extra)
    assert spec.rules and spec.behaviours


def test_robot_specs_have_the_papers_shape():
    kobuki = load_spec(os.path.join(ROOT, "config", "kobuki.rbs"))
    assert len({r.entity for r in kobuki.rules}) == 1 and len(kobuki.rules) == 4
    frobit = load_spec(os.path.join(ROOT, "config", "frobit.rbs"))
    assert len({r.entity for r in frobit.rules}) == 3 and len(frobit.rules) == 9
    spins = {}
    for variant, seconds in (("kobuki.rbs", 0.7), ("kobuki_spin_0.2s.rbs", 0.2), ("kobuki_spin_0s.rbs", 0.0)):
        rule = load_spec(os.path.join(ROOT, "config", variant)).rule("base.spinning")
        spins[variant] = rule.expr.duration.value
        assert spins[variant] == pytest.approx(seconds)
