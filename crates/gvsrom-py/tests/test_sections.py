"""Rectangular and elliptical sections through the Python API: a preset of circular sections
turned into a rectangle by ``Scenario.set`` (the circle's radius dropped with it), whose bending
strain under the same moment is the circle's scaled by the ratio of the bending stiffnesses —
``EI_y = E w h³/12`` about the section's y axis, the height along z."""

import math

import numpy as np
import pytest

import gvsrom


def _rectangle(w, h):
    return (gvsrom.Scenario.preset("soft-beam").set("divisions.0.section", "rectangle")
            .set("divisions.0.width", w).set("divisions.0.height", h))


def test_a_rectangle_bends_about_y_with_its_height_cubed():
    # the soft beam's moment bends it about local y: planar, κ(X) = M(X)/EI_y pointwise, and the
    # Galerkin strain is linear in 1/EI_y, so the ratio to the circle's is exact
    circle = gvsrom.Scenario.preset("soft-beam").build().statics().strain[:, 1]
    ei_circle = math.pi * 0.015 ** 4 / 4
    for w, h in [(0.03, 0.02), (0.02, 0.03)]:
        scenario = _rectangle(w, h)
        assert "radius" not in scenario.to_toml()
        strain = scenario.build().statics().strain[:, 1]
        np.testing.assert_allclose(strain, circle * ei_circle / (w * h ** 3 / 12), rtol=1e-9, atol=1e-10)


def test_an_ellipse_of_equal_axes_is_the_circle():
    circle = gvsrom.Scenario.preset("soft-beam").build().statics()
    round_ = (gvsrom.Scenario.preset("soft-beam").set("divisions.0.section", "ellipse")
              .set("divisions.0.width", 0.03).set("divisions.0.height", 0.03).build().statics())
    np.testing.assert_allclose(round_.strain, circle.strain, rtol=1e-12, atol=1e-12)


def test_a_section_without_its_sizes_is_refused_naming_the_field():
    with pytest.raises(gvsrom.GvsromError, match=r"divisions\[0\]\.height.*missing"):
        gvsrom.Scenario.preset("soft-beam").set("divisions.0.section", "rectangle").set(
            "divisions.0.width", 0.03).build()


def test_a_tube_bends_by_the_stiffness_its_bore_removes():
    # a bore of radius r_i leaves (r⁴ − r_i⁴)/r⁴ of the circle's bending stiffness: under the
    # same moment the Galerkin strain is the circle's divided by it, exactly
    circle = gvsrom.Scenario.preset("soft-beam").build().statics().strain[:, 1]
    r, r_i = 0.015, 0.01
    tube = gvsrom.Scenario.preset("soft-beam").set("divisions.0.inner_radius", r_i)
    assert "inner_radius = 0.01" in tube.to_toml()
    strain = tube.build().statics().strain[:, 1]
    np.testing.assert_allclose(strain, circle / (1 - (r_i / r) ** 4), rtol=1e-9, atol=1e-10)
    with pytest.raises(gvsrom.GvsromError, match=r"divisions\[0\]\.inner_radius.*0\.015"):
        gvsrom.Scenario.preset("soft-beam").set("divisions.0.inner_radius", 0.015).build()
