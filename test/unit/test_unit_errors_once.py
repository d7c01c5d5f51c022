"""An unknown unit is one error at its place (not a second one for the `for` it times), and a model
file's unit typo gets a suggestion of its own dimension ('m/sec' -> 'm/s', not 'sec')."""
import pytest

from rubass.lang import SpecError, check_text
from rubass.lang.modelfile import load_model
from rubass.lang.source import SourceSet

HEAD = 'action primitive stop;\n'


def test_an_unknown_unit_of_a_for_is_one_error():
    with pytest.raises(SpecError) as err:
        check_text(HEAD + "entity e { rules: r: (topic /a.data > 1) for 500 msec; }\nif (e.r) then { stop; }\n")
    messages = [d.message for d in err.value.diagnostics if d.severity == "error" and "action" not in d.message]
    assert messages == ["unknown unit 'msec'; did you mean 'ms'?"], messages


def test_a_model_files_unit_typo_gets_a_suggestion_of_its_dimension(write):
    path = write("m.yaml", "rubass_model: 1\ntopics:\n  /bms: acme/Pack\ndefinitions:\n  acme/Pack: |\n"
                           "    float64 pack_voltage\nunits:\n  acme/Pack: {pack_voltage: m/sec}\n")
    model, diags = load_model(path, SourceSet())
    text = "\n".join(d.message for d in diags)
    assert model is None and "'m/sec' is not an SI unit" in text and "did you mean 'm/s'?" in text, text


def test_a_unit_that_divides_gives_the_decimal_meant():
    """70 % was 70 * 0.01 = 0.7000000000000001, so `cpu(node n) >= 70 %` was false at exactly 0.7
    (acceptance sweep); a factor 1/n (or 5/18 for km/h) is applied as a division."""
    from rubass.lang import check_text
    from rubass.lang.units import parse_quantity

    c = check_text("const P = 70 %;\nconst V = 36 km/h;\nconst T = 70 ms;\nconst A = 30 deg;\n")
    assert c.consts == {"P": 0.7, "V": 10.0, "T": 0.07, "A": 30 * 3.141592653589793 / 180}
    assert parse_quantity("70 %") == (0.7, parse_quantity("1 %")[1])
    assert parse_quantity("1e308 km/h")[0] == 1e308 / 3.6  # not an overflow of 1e308 * 5 on the way


def test_a_formula_of_dimensions_names_no_internal_base():
    """'a quantity in geo_deg*s^-1' showed the checker's own name for NavSatFix degrees (acceptance sweep)."""
    from rubass.lang.units import dim, dimension_name

    assert dimension_name(dim(geo_deg=1, s=-1)) == "deg(lat/lon)*s^-1"
