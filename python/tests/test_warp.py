"""penumbra.warp: the samples' pdf is the routine's pdf; samples have the claimed density."""

import numpy as np
import pytest

import penumbra

ROUTINES = [
    ("cosine-hemisphere", None),
    ("sphere", None),
    ("cosine-power", {"n": 20}),
    ("cone", {"angle": 50}),
    ("spherical-triangle", None),
    ("ggx", {"alpha": 0.2, "theta": 60}),
    ("phong", ["n=50", "ks=0.5"]),
    ("coated-diffuse", None),
    ("disk", None),
    ("triangle", {"a": (0, 0)}),
]


@pytest.mark.parametrize("name, params", ROUTINES)
def test_sample_pdf_matches_pdf(name, params):
    x, p = penumbra.warp.sample(name, 20000, params=params)
    assert x.dtype == np.float32 and p.dtype == np.float64
    assert len(x) == len(p) > 1000
    q = penumbra.warp.pdf(name, x, params=params)
    np.testing.assert_allclose(q, p, rtol=2e-5)
    assert np.all(p > 0)


@pytest.mark.parametrize("name", ["cosine-hemisphere", "sphere"])
def test_mean_inverse_pdf_is_the_domain_measure(name):
    # E[1/p(X)] = measure of the support (2π for the hemisphere, 4π for the sphere): a check
    # an external harness can make, within 5 standard errors.
    x, p = penumbra.warp.sample(name, 200000, pattern="random", seed=5)
    est = 1.0 / p
    want = {"cosine-hemisphere": 2 * np.pi, "sphere": 4 * np.pi}[name]
    assert abs(est.mean() - want) < 5 * est.std() / np.sqrt(len(est)) + 1e-6 * want


def test_patterns_and_seeds_change_the_samples():
    a, _ = penumbra.warp.sample("disk", 256, pattern="sobol")
    b, _ = penumbra.warp.sample("disk", 256, pattern="random", seed=1)
    c, _ = penumbra.warp.sample("disk", 256, pattern="random", seed=1)
    assert a.shape[1] == 2 and not np.array_equal(a, b) and np.array_equal(b, c)


def test_bad_names_raise_value_error_listing_choices():
    with pytest.raises(ValueError, match="cosine-hemisphere"):
        penumbra.warp.sample("nope", 10)
    with pytest.raises(ValueError, match="expected one of: fixed"):
        penumbra.warp.sample("disk", 10, pattern="nope")
    with pytest.raises(ValueError, match="valid keys"):
        penumbra.warp.sample("cosine-power", 10, params={"bogus": 1})
    with pytest.raises(ValueError, match="coordinates"):
        penumbra.warp.pdf("sphere", np.zeros((4, 2)))
