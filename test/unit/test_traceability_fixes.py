"""Traceability fixes of issue 16: an entity's @id is a known id, duplicate ids in source order, bad
report inputs exit 1, one gap is "1 gap"."""
import os

import pytest

from rubass.lang import SpecError, check_text

from conftest import ROOT


def check_errors(text, tmp_path):
    path = str(tmp_path / "dupid2.rbs")
    with open(path, "w") as fh:
        fh.write(text)
    with pytest.raises(SpecError) as exc:
        check_text(text, path, [os.path.join(ROOT, "docs", "examples", "actions.yaml")])
    return exc.value.render()


def test_duplicate_id_is_reported_at_the_later_place(tmp_path):
    text = ('import "actions.yaml";\naction primitive stop;\n@id("A") entity base { rules: r: topic /v.x > 1; }\n'
            '@id("A") if (base.r) then { stop; }\n@id("A") if (base.r) then { stop; }\n')
    rendered = check_errors(text, tmp_path)
    errors = [line for line in rendered.splitlines() if "duplicate id" in line]
    assert len(errors) == 2
    assert errors[0].startswith(f"{tmp_path}/dupid2.rbs:4:1: error: duplicate id \"A\"; first given at "
                                f"{tmp_path}/dupid2.rbs:3:1")
    assert errors[1].startswith(f"{tmp_path}/dupid2.rbs:5:1:") and errors[1].endswith("dupid2.rbs:3:1")


def test_duplicate_id_of_a_rule_and_a_later_entity(tmp_path):
    text = ('import "actions.yaml";\naction primitive stop;\nentity a { rules: @id("X") r: topic /v.x > 1; }\n'
            '@id("X") entity b { rules: q: topic /v.x > 2; }\nif (a.r or b.q) then { stop; }\n')
    (error,) = [line for line in check_errors(text, tmp_path).splitlines() if "duplicate id" in line]
    assert error.startswith(f"{tmp_path}/dupid2.rbs:4:1:") and error.endswith("dupid2.rbs:3:19")
