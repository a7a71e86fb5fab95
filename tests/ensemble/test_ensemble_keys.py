"""Key paths into the resolved scenario: parsing, lookup, a breach's implied defaults."""

from __future__ import annotations

import pytest

from floodsph.breach import formulas
from floodsph.ensemble.keys import MISSING, KeyPath, KeyPathError, assign, base_value, lookup

BASE = {
    "scenario": {"name": "v", "end_time_s": 600.0},
    "terrain": {"dem": "/data/dem.tif", "manning": 0.035},
    "inflows": [{"line": [[0.0, 0.0], [0.0, 10.0]], "direction": [1.0, 0.0],
                 "breach": {"method": "froehlich2008", "reservoir_volume_m3": 2.3e6,
                            "breach_height_m": 9.0, "breach_invert_m": 225.0}}],
    "numerics": {"cfl": 0.3},
}


def test_parse_keeps_keys_and_indices():
    key = KeyPath.parse("inflows[0].direction[1]")
    assert key.tokens == ("inflows", 0, "direction", 1)
    assert key.pattern == "inflows[].direction[]"


@pytest.mark.parametrize("text", ["inflows.[0]", "terrain..manning", "1st.key", "a[-1]", ""])
def test_parse_refuses_malformed_paths(text):
    with pytest.raises(KeyPathError, match="is not a key path"):
        KeyPath.parse(text)


def test_lookup_reaches_values_inside_arrays():
    assert lookup(BASE, KeyPath.parse("inflows[0].direction[1]")) == 0.0
    assert lookup(BASE, KeyPath.parse("inflows[0].breach.breach_height_m")) == 9.0


def test_lookup_of_an_accepted_key_left_to_its_default_is_missing():
    assert lookup(BASE, KeyPath.parse("numerics.particle_spacing_m")) is MISSING
    assert lookup(BASE, KeyPath.parse("inflows[0].breach.average_width_m")) is MISSING


def test_breach_width_and_formation_time_factor_the_froehlich_values():
    """A factor on a breach width or formation time that the base leaves out multiplies what
    Froehlich (2008) gives for the base's reservoir and breach height."""
    width = base_value(BASE, KeyPath.parse("inflows[0].breach.average_width_m"))
    t_f = base_value(BASE, KeyPath.parse("inflows[0].breach.formation_time_s"))
    assert width == pytest.approx(
        formulas.froehlich2008_average_width(2.3e6, 9.0, "overtopping"), rel=1e-12)
    assert t_f == pytest.approx(formulas.froehlich2008_formation_time(2.3e6, 9.0), rel=1e-12)
    assert base_value(BASE, KeyPath.parse("inflows[0].breach.weir_coefficient")) == (
        formulas.WEIR_COEFFICIENT)


def test_assign_leaves_the_base_alone():
    key = KeyPath.parse("inflows[0].breach.breach_height_m")
    changed = assign(BASE, key, 7.5)
    assert lookup(changed, key) == 7.5
    assert lookup(BASE, key) == 9.0
