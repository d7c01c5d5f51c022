"""The risk table of `rubass report --hazards`: every error `FILE:LINE:COL: error: …`, all at once; the
fields docs/report.md defines checked (ids are text, a title, ISO 13849-1 severity/exposure/avoidance)."""
import os

import pytest

from conftest import ROOT

from rubass.cli import main
from rubass.report.hazards import HazardsError, read_hazards

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
SPEC = f'import "{LIB}";\n' + 'action primitive stop;\nentity base {\n  rules:\n    @hazard("H1") fast: topic /v.data > 1;\n}\n' \
    'if (base.fast) then { stop; }\n'


def errors(write, text):
    path = write("risk.yaml", text)
    with pytest.raises(HazardsError) as exc:
        read_hazards(path)
    return path, exc.value.lines


def test_a_yaml_error_is_at_its_place_not_pyyaml_text(write):
    path, lines = errors(write, "hazards:\n  - {id: H1, title: [x\n")
    assert lines == [f"{path}:3:1: error: not valid YAML: expected ',' or ']', but got '<stream end>' "
                     f"(while parsing a flow sequence at 2:21)"]
    assert "<unicode string>" not in lines[0]


def test_every_error_is_reported_at_once_in_the_order_of_the_text(write):
    path, lines = errors(write, "hazards:\n  - id: H1\n    title: x\n  - id: H1\n    title: dup\n"
                                "  - title: no id\n  - id: 7\n    title: number\n  - id: H3\n    severity: S9\n"
                                "    exposure: F3\n    avoidance: p1\n    bogus: {a: 1}\n")
    assert lines == [
        f"{path}:4:9: error: hazard H1 is given twice; first at {path}:2:9 (each id once: the matrix would "
        "not know which row is meant)",
        f"{path}:6:5: error: hazard 3 has no id (id: H…, the id that rules name with @hazard(\"H…\"))",
        f"{path}:7:9: error: hazard 4: the id must be a text (as @hazard(\"…\") names it), not a number (7): "
        "write id: '7' or id: H7",
        f"{path}:9:5: error: hazard 5 (H3) has no title (title: what can go wrong, as in the risk assessment)",
        f"{path}:10:15: error: hazard 5: severity 'S9' is not one of S1 (slight, normally reversible injury), "
        "S2 (serious, irreversible injury or death) (ISO 13849-1 risk graph)",
        f"{path}:11:15: error: hazard 5: exposure 'F3' is not one of F1 (seldom to less often, or short "
        "exposure), F2 (frequent to continuous, or long exposure) (ISO 13849-1 risk graph)",
        f"{path}:12:16: error: hazard 5: avoidance 'p1' is not one of P1 (possible under specific conditions), "
        "P2 (scarcely possible) (ISO 13849-1 risk graph)",
        f"{path}:13:12: error: hazard 5: 'bogus' must be a plain value shown beside the hazard, not a mapping",
        f"{path}: 8 errors"]


@pytest.mark.parametrize("text, line", [
    ("hazard:\n  - {id: H1, title: x}\n", "1:1: error: unknown key 'hazard': expected 'hazards:'"),
    ("- {id: H1, title: x}\n", "1:1: error: expected 'hazards:' with a list of hazards"),
    ("", "1:1: error: the risk table is empty"),
    ("hazards: H1\n", "1:10: error: expected 'hazards:' to be a list of hazards"),
    ("hazards:\n  - H1\n", "2:5: error: hazard 1 must be a mapping {id: H1, title: …}, not a text"),
    ("hazards:\n  - {id: H1, title: x, id: H2}\n", "2:24: error: hazard 1: 'id' is given twice; first at"),
    ("hazards:\n  - {id: H1, title: }\n", "2:20: error: hazard 1: the title must be a text, not empty"),
    ("hazards:\n  - {id: '', title: x}\n", "2:10: error: hazard 1: the id must be a text (as @hazard(\"…\") names it), not an empty text"),
])
def test_the_shape_of_the_table_is_checked_at_its_place(write, text, line):
    path, lines = errors(write, text)
    assert lines[0].startswith(f"{path}:{line}"), lines


def test_a_good_table_keeps_its_details(write):
    path = write("risk.yaml", "hazards:\n  - {id: H1, title: Collision, severity: S2, exposure: F1, avoidance: P2, "
                              "plr: d, note: 3}\n  - {id: '7', title: Quoted}\n")
    h1, h7 = read_hazards(path)
    assert (h1.id, h1.title, h1.details) == ("H1", "Collision", {"severity": "S2", "exposure": "F1",
                                                                  "avoidance": "P2", "plr": "d", "note": "3"})
    assert (h7.id, h7.title) == ("7", "Quoted")


def test_the_command_prints_them_and_writes_no_page(write, tmp_path, capsys):
    spec = write("s.rbs", SPEC)
    risk = write("risk.yaml", "# risk\nhazards:\n  - id: H1\n    severity: S9\n  - {id: H1, title: x}\n")
    out = tmp_path / "r.html"
    assert main(["report", spec, "--hazards", risk, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert f"{risk}:3:5: error: hazard 1 (H1) has no title" in err
    assert f"{risk}:4:15: error: hazard 1: severity 'S9' is not one of S1" in err
    assert f"{risk}:5:10: error: hazard H1 is given twice; first at {risk}:3:9" in err
    assert "rubass report: error" not in err and not out.exists()
