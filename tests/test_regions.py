"""specrefine.core.regions: membership, signed distance, sampling, subset test, JSON round trip."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specrefine.core.regions import Box, Disc, Region, Union, from_dict, is_subset, union

# --- membership ------------------------------------------------------------------


def test_box_contains_batch_with_closed_boundary():
    b = Box(0, 0, 2, 1)
    pts = np.array([[1, 0.5], [0, 0], [2, 1], [2, 0.5], [2.001, 0.5], [-1, -1], [1, 1.0001]])
    assert b.contains(pts).tolist() == [True, True, True, True, False, False, False]


def test_contains_keeps_leading_batch_shape():
    pts = np.zeros((3, 4, 2))
    pts[1, 2] = [10, 10]
    inside = Disc(0, 0, 1).contains(pts)
    assert inside.shape == (3, 4)
    assert inside.sum() == 11 and not inside[1, 2]


def test_single_point_gives_scalar_answer():
    assert bool(Box(0, 0, 1, 1).contains([0.5, 0.5]))
    assert np.ndim(Box(0, 0, 1, 1).signed_distance([0.5, 0.5])) == 0


def test_disc_contains():
    d = Disc(1, 1, 2)
    pts = [[1, 1], [3, 1], [1, -1], [2.5, 2.5], [3.01, 1]]
    assert d.contains(pts).tolist() == [True, True, True, False, False]


def test_union_contains_any_member():
    u = Union((Box(0, 0, 1, 1), Disc(5, 5, 1)))
    assert u.contains([[0.5, 0.5], [5.5, 5.5], [3, 3], [1.5, 0.5]]).tolist() == [True, True, False, False]


def test_points_must_be_two_dimensional():
    with pytest.raises(ValueError, match="trailing dimension of 2"):
        Box(0, 0, 1, 1).contains([[1, 2, 3]])


def test_degenerate_regions_are_rejected():
    with pytest.raises(ValueError):
        Box(0, 0, 0, 1)
    with pytest.raises(ValueError):
        Box(1, 0, 0, 1)
    with pytest.raises(ValueError):
        Disc(0, 0, 0)
    with pytest.raises(ValueError):
        Union(())


# --- signed distance -------------------------------------------------------------


def test_box_signed_distance_hand_values():
    b = Box(0, 0, 2, 1)
    pts = [[1, 0.5], [0.2, 0.5], [3, 0.5], [3, 2], [0, 0], [1, 1], [-3, -4 + 0]]
    np.testing.assert_allclose(b.signed_distance(pts), [-0.5, -0.2, 1.0, np.sqrt(2), 0.0, 0.0, np.hypot(3, 4)])


def test_disc_signed_distance_hand_values():
    d = Disc(1, 2, 3)
    np.testing.assert_allclose(d.signed_distance([[1, 2], [4, 2], [1, 7], [1 + 3 * 0.6, 2 + 3 * 0.8]]),
                               [-3, 0, 2, 0], atol=1e-12)


def test_union_signed_distance_sign_and_outside_value():
    u = Union((Box(0, 0, 1, 1), Box(3, 0, 4, 1)))
    sd = u.signed_distance([[0.5, 0.5], [3.5, 0.5], [2, 0.5], [1, 0.5], [5, 0.5]])
    assert sd[0] < 0 and sd[1] < 0
    np.testing.assert_allclose(sd[2:], [1.0, 0.0, 1.0])


def test_signed_distance_negative_inside_positive_outside_on_samples():
    rng = np.random.default_rng(0)
    for r in (Box(-1, -2, 3, 0.5), Disc(0.3, -0.2, 1.7), Union((Box(0, 0, 1, 1), Disc(2, 2, 0.5)))):
        inside = r.sample(200, rng)
        assert np.all(r.signed_distance(inside) <= 0)
        x0, y0, x1, y1 = r.bounds()
        far = np.array([[x1 + 0.1, y1 + 0.1], [x0 - 1, y0], [x1 + 5, (y0 + y1) / 2]])
        assert np.all(r.signed_distance(far) > 0)


# --- sampling --------------------------------------------------------------------

REGIONS = [
    Box(-1, 2, 4, 3),
    Disc(1, 1, 0.5),
    Union((Box(0, 0, 1, 1), Box(0.5, 0.5, 2, 2), Disc(-3, 0, 1))),
]


@pytest.mark.parametrize("region", REGIONS, ids=["box", "disc", "union"])
def test_sampling_is_seeded_and_inside(region):
    a = region.sample(500, np.random.default_rng(42))
    b = region.sample(500, np.random.default_rng(42))
    c = region.sample(500, np.random.default_rng(43))
    assert a.shape == (500, 2)
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)
    assert region.contains(a).all()


def test_box_sampling_covers_the_box_uniformly():
    pts = Box(0, 0, 4, 1).sample(8000, np.random.default_rng(1))
    counts = np.histogram(pts[:, 0], bins=4, range=(0, 4))[0]
    np.testing.assert_allclose(counts / 8000, 0.25, atol=0.03)


def test_disc_sampling_is_uniform_by_area():
    pts = Disc(0, 0, 2).sample(8000, np.random.default_rng(2))
    inner = (np.hypot(pts[:, 0], pts[:, 1]) <= 1).mean()  # inner disc has 1/4 of the area
    assert inner == pytest.approx(0.25, abs=0.03)


def test_union_sampling_weights_members_by_area():
    small, big = Box(0, 0, 1, 1), Box(10, 0, 13, 1)  # areas 1 and 3
    pts = Union((small, big)).sample(8000, np.random.default_rng(3))
    assert small.contains(pts).mean() == pytest.approx(0.25, abs=0.03)
    assert big.contains(pts).mean() == pytest.approx(0.75, abs=0.03)


def test_union_sampling_does_not_double_count_overlaps():
    # two boxes overlapping in [1,2]x[0,1]; the union is [0,3]x[0,1], so x is uniform on [0,3]
    pts = Union((Box(0, 0, 2, 1), Box(1, 0, 3, 1))).sample(9000, np.random.default_rng(4))
    frac_overlap = ((pts[:, 0] >= 1) & (pts[:, 0] <= 2)).mean()
    assert frac_overlap == pytest.approx(1 / 3, abs=0.03)


def test_area_and_centre():
    assert Box(0, 0, 2, 3).area == 6
    assert Disc(0, 0, 2).area == pytest.approx(4 * np.pi)
    assert Union((Box(0, 0, 2, 1), Box(1, 0, 3, 1))).area == pytest.approx(3.0)
    for r in REGIONS:
        assert bool(r.contains(r.centre()))
    assert union([Box(0, 0, 1, 1)]) == Box(0, 0, 1, 1)


# --- is_subset -------------------------------------------------------------------


def test_box_in_box():
    assert is_subset(Box(1, 1, 2, 2), Box(0, 0, 3, 3))
    assert is_subset(Box(0, 0, 3, 3), Box(0, 0, 3, 3))
    assert not is_subset(Box(1, 1, 4, 2), Box(0, 0, 3, 3))
    assert not is_subset(Box(0, 0, 3, 3), Box(1, 1, 2, 2))


def test_box_covered_only_by_two_boxes_together():
    outer = Union((Box(0, 0, 1, 1), Box(1, 0, 2, 1)))
    inner = Box(0.5, 0.2, 1.5, 0.8)
    assert not is_subset(inner, Box(0, 0, 1, 1)) and not is_subset(inner, Box(1, 0, 2, 1))
    assert is_subset(inner, outer)
    assert not is_subset(Box(0.5, 0.2, 1.5, 1.2), outer)


def test_box_covered_by_three_boxes_with_a_gap_is_rejected():
    outer = Union((Box(0, 0, 1, 1), Box(2, 0, 3, 1)))
    assert not is_subset(Box(0.5, 0.2, 2.5, 0.8), outer)
    assert is_subset(Box(0.5, 0.2, 2.5, 0.8), Union((*outer.parts(), Box(1, 0, 2, 0.9))))


def test_l_shaped_union_rejects_the_missing_corner():
    ell = Union((Box(0, 0, 2, 1), Box(0, 1, 1, 2)))
    assert is_subset(Box(0.2, 0.2, 0.8, 1.8), ell)
    assert not is_subset(Box(0.2, 0.2, 1.8, 1.8), ell)


def test_disc_in_box_and_in_union_of_boxes():
    assert is_subset(Disc(1, 1, 1), Box(0, 0, 2, 2))
    assert not is_subset(Disc(1, 1, 1.01), Box(0, 0, 2, 2))
    two = Union((Box(0, 0, 1, 1), Box(1, 0, 2, 1)))
    assert is_subset(Disc(1, 0.5, 0.5), two)
    assert not is_subset(Disc(1, 0.5, 0.55), two)
    # a disc across the inside corner of an L: the corner cell is missing
    ell = Union((Box(0, 0, 2, 1), Box(0, 1, 1, 2)))
    assert is_subset(Disc(0.5, 1.0, 0.5), ell)
    assert not is_subset(Disc(1.1, 1.1, 0.3), ell)


def test_disc_in_disc():
    assert is_subset(Disc(0, 0, 1), Disc(0, 0, 2))
    assert is_subset(Disc(1, 0, 1), Disc(0, 0, 2))  # internally tangent
    assert not is_subset(Disc(1.1, 0, 1), Disc(0, 0, 2))
    assert not is_subset(Disc(0, 0, 2), Disc(0, 0, 1))


def test_box_in_disc():
    assert is_subset(Box(-0.7, -0.7, 0.7, 0.7), Disc(0, 0, 1))
    assert not is_subset(Box(-0.8, -0.8, 0.8, 0.8), Disc(0, 0, 1))


def test_union_inner_needs_every_member_inside():
    outer = Box(0, 0, 10, 10)
    assert is_subset(Union((Box(1, 1, 2, 2), Disc(5, 5, 1))), outer)
    assert not is_subset(Union((Box(1, 1, 2, 2), Disc(9.5, 5, 1))), outer)


def test_boxes_of_a_mixed_outer_union_still_cover():
    outer = Union((Box(0, 0, 1, 1), Box(1, 0, 2, 1), Disc(10, 10, 1)))
    assert is_subset(Box(0.5, 0.2, 1.5, 0.8), outer)


def test_subset_forgives_round_off_but_not_real_excess():
    outer = Union((Box(0, 0, 0.1 + 0.2, 1), Box(0.3, 0, 1, 1)))
    assert is_subset(Box(0.1, 0.1, 0.9, 1 + 1e-12), outer)
    assert not is_subset(Box(0.1, 0.1, 0.9, 1 + 1e-3), outer)


# --- JSON round trip -------------------------------------------------------------


@pytest.mark.parametrize("region", REGIONS + [Union((Box(0, 0, 1, 1),))], ids=["box", "disc", "union", "union1"])
def test_json_round_trip(region):
    d = json.loads(json.dumps(region.to_dict()))
    back = from_dict(d)
    assert back == region
    assert type(back) is type(region)
    assert back.to_dict() == region.to_dict()


def test_from_dict_rejects_unknown_type():
    with pytest.raises(ValueError, match="unknown region type"):
        from_dict({"type": "triangle"})


def test_nested_unions_are_flattened():
    u = Union((Union((Box(0, 0, 1, 1), Box(2, 2, 3, 3))), Disc(0, 0, 1)))
    assert len(u.parts()) == 3 and all(not isinstance(p, Union) for p in u.parts())


# --- property tests (hypothesis) -------------------------------------------------

coord = st.floats(-20, 20, allow_nan=False, allow_infinity=False)
size = st.floats(0.05, 10, allow_nan=False, allow_infinity=False)


@st.composite
def boxes(draw):
    x, y, w, h = draw(coord), draw(coord), draw(size), draw(size)
    return Box(x, y, x + w, y + h)


@st.composite
def discs(draw):
    return Disc(draw(coord), draw(coord), draw(size))


simple = st.one_of(boxes(), discs())


@st.composite
def regions(draw):
    members = draw(st.lists(simple, min_size=1, max_size=4))
    return members[0] if len(members) == 1 else Union(tuple(members))


def _near_or_inside(region: Region, pts, tol=1e-7):
    return region.signed_distance(pts) <= tol


@settings(max_examples=60, deadline=None)
@given(regions(), st.integers(0, 2**32 - 1))
def test_prop_samples_are_inside(region, seed):
    pts = region.sample(64, np.random.default_rng(seed))
    assert pts.shape == (64, 2)
    assert np.all(_near_or_inside(region, pts))


@settings(max_examples=60, deadline=None)
@given(regions(), regions())
def test_prop_region_is_subset_of_itself_and_of_union(a, b):
    assert is_subset(a, a)
    assert is_subset(a, Union((a, b)))
    assert is_subset(a, Union((b, a)))


@settings(max_examples=60, deadline=None)
@given(boxes(), st.lists(st.floats(0, 1), min_size=4, max_size=4))
def test_prop_random_sub_box_is_subset(outer, u):
    (fx0, fx1), (fy0, fy1) = sorted(u[:2]), sorted(u[2:])
    w, h = outer.xmax - outer.xmin, outer.ymax - outer.ymin
    if fx1 - fx0 < 1e-3 or fy1 - fy0 < 1e-3:
        return
    inner = Box(outer.xmin + fx0 * w, outer.ymin + fy0 * h, outer.xmin + fx1 * w, outer.ymin + fy1 * h)
    assert is_subset(inner, outer)
    # and the sub-box is inside any union holding the outer box, even when split in two halves
    mid = (outer.xmin + outer.xmax) / 2
    halves = Union((Box(outer.xmin, outer.ymin, mid, outer.ymax), Box(mid, outer.ymin, outer.xmax, outer.ymax)))
    assert is_subset(inner, halves)


@settings(max_examples=150, deadline=None)
@given(regions(), regions(), st.integers(0, 2**32 - 1))
def test_prop_is_subset_is_sound(inner, outer, seed):
    if not is_subset(inner, outer):
        return
    pts = inner.sample(200, np.random.default_rng(seed))
    assert np.all(_near_or_inside(outer, pts))


@settings(max_examples=100, deadline=None)
@given(st.lists(boxes(), min_size=1, max_size=4), st.lists(boxes(), min_size=1, max_size=4),
       st.integers(0, 2**32 - 1))
def test_prop_is_subset_is_sound_for_box_unions(inner_boxes, outer_boxes, seed):
    # boxes snapped to a coarse grid make covering by several boxes together common
    snap = [Box(round(b.xmin), round(b.ymin), round(b.xmin) + max(1, round(b.xmax - b.xmin)),
                round(b.ymin) + max(1, round(b.ymax - b.ymin))) for b in outer_boxes]
    inner = union(Box(round(b.xmin) + 0.25, round(b.ymin) + 0.25, round(b.xmin) + 1.75, round(b.ymin) + 0.75)
                  for b in inner_boxes)
    outer = union(snap)
    claimed = is_subset(inner, outer)
    pts = inner.sample(400, np.random.default_rng(seed))
    if claimed:
        assert np.all(_near_or_inside(outer, pts))
    elif np.all(outer.contains(pts)):
        # exact for unions of boxes: a 'no' must have a witness; look on a fine grid inside the inner set
        grid = np.stack(np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41)), -1).reshape(-1, 2)
        witnesses = [p.bounds() for p in inner.parts()]
        found = False
        for x0, y0, x1, y1 in witnesses:
            g = np.column_stack([x0 + grid[:, 0] * (x1 - x0), y0 + grid[:, 1] * (y1 - y0)])
            found |= bool(np.any(~outer.contains(g)))
        assert found, "is_subset said no for boxes that cover the inner set"
