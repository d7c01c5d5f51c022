"""The pretty-printer: canonical, idempotent, keeps comments, parse(fmt(x)) == parse(x)."""
import glob
import os

import pytest

from rubass.lang import format_spec, parse_text

from conftest import ROOT

FIG2 = open(os.path.join(ROOT, "config", "fig2.rbs"), encoding="utf-8").read()


def test_fig2_formats_to_the_papers_layout():
    assert format_spec(parse_text(FIG2), FIG2) == (
        "action primitive stop;\n"
        "\n"
        "entity drive_system: encoder_node, actuator_node {\n"
        "  rules:  // simple example comprising one actuator\n"
        "    actuator_erratic:\n"
        "      ((topic /cmd_vel_left.linear.x > 0.02 m/s or topic /cmd_vel_left.linear.x < -0.02 m/s)\n"
        "       and topic /encoder_left.data == 0) for 0.4 sec;\n"
        "}\n"
        "\n"
        "if (drive_system.actuator_erratic for 1 sec) then { stop; }\n"
    )


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(ROOT, "config", "*.rbs"))))
def test_round_trip_and_idempotent_on_configs(path):
    text = open(path, encoding="utf-8").read()
    once = format_spec(parse_text(text), text)
    assert parse_text(once) == parse_text(text)
    assert format_spec(parse_text(once), once) == once


def test_configs_other_than_fig2_are_canonical():
    for path in glob.glob(os.path.join(ROOT, "config", "*.rbs")):
        if path.endswith("fig2.rbs"):
            continue  # kept exactly as printed in LANGUAGE.md
        text = open(path, encoding="utf-8").read()
        assert format_spec(parse_text(text), text) == text, path


def test_parentheses_only_where_needed_and_kept_where_meaningful():
    src = "const a = (1 - (2 - 3)) * -(4 + 5) / 2;\nconst b = not (true and false) or (true or false) and true;\n"
    out = format_spec(parse_text(src))
    assert out == ("const a = (1 - (2 - 3)) * -(4 + 5) / 2;\n"
                   "const b = not (true and false) or (true or false) and true;\n")
    assert parse_text(out) == parse_text(src)


def test_comments_are_kept_in_place():
    src = ("// header\nimport \"a.yaml\";  // lib\n\n// consts\nconst A = 1 s;\n"
           "entity e {\n  rules:\n    // leading\n    r: topic /x.y > 1;  // trailing\n    // last\n}\n// end\n")
    out = format_spec(parse_text(src), src)
    assert out == ("// header\nimport \"a.yaml\";  // lib\n\n// consts\nconst A = 1 s;\n\n"
                   "entity e {\n  rules:\n    // leading\n    r: topic /x.y > 1;  // trailing\n    // last\n}\n\n// end\n")
    assert format_spec(parse_text(out), out) == out


def test_strings_and_numbers_round_trip():
    src = 'action primitive log;\n\nif (true) then { log("a \\"q\\" \\\\ b", 1e-06, 0.1, 12); }\n'
    assert format_spec(parse_text(src)) == src
