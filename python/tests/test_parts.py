"""Sample ranges: parts of a render merge to the whole render."""

import itertools

import numpy as np
import pytest

import penumbra

SPP = 24
RES = (40, 24)
RANGES = [(0, 5), (5, 6), (6, 17), (17, 24)]


@pytest.fixture(scope="module")
def scene():
    return penumbra.load("cornell")


@pytest.fixture(scope="module")
def whole(scene):
    return scene.render(spp=SPP, res=RES)


@pytest.fixture(scope="module")
def parts(scene):
    return [(scene.render(spp=SPP, res=RES, spp_range=r), r) for r in RANGES]


def max_rel(a, b):
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-6)))


def test_parts_merge_to_the_whole_render(whole, parts):
    merged = penumbra.merge(parts, spp=SPP)
    assert max_rel(merged, whole) < 1e-5
    # The parts are different estimates: merging them is not a no-op.
    assert max_rel(parts[0][0], whole) > 1e-2


def test_merge_is_bit_identical_in_any_order(parts):
    first = penumbra.merge(parts, spp=SPP)
    for perm in itertools.permutations(parts):
        assert np.array_equal(penumbra.merge(list(perm), spp=SPP), first)


def test_the_whole_range_is_the_whole_render(scene, whole):
    assert np.array_equal(scene.render(spp=SPP, res=RES, spp_range=(0, SPP)), whole)


@pytest.mark.parametrize(
    "drop, text",
    [([1], "samples 5..6 are missing"), ([3], "samples 17..24 are missing")],
)
def test_missing_part_is_an_error(parts, drop, text):
    with pytest.raises(ValueError, match=text):
        penumbra.merge([p for i, p in enumerate(parts) if i not in drop], spp=SPP)


def test_overlapping_parts_are_an_error(scene, parts):
    extra = (scene.render(spp=SPP, res=RES, spp_range=(4, 7)), (4, 7))
    with pytest.raises(ValueError, match="overlap"):
        penumbra.merge(parts + [extra], spp=SPP)


def test_cli_parts_merge_like_python_parts(cli, tmp_path, parts, whole):
    files = []
    for a, b in RANGES:
        f = tmp_path / f"part-{a}-{b}.exr"
        cli("render", "cornell", "--res", "40x24", "--spp", SPP, "--spp-range", f"{a}..{b}", "-q", "-o", f)
        files.append(f)
    for (arr, _), f in zip(parts, files):
        assert np.array_equal(penumbra.read_image(f), arr)
    cli("merge", *reversed(files), "-o", tmp_path / "merged.exr")
    by_cli = penumbra.read_image(tmp_path / "merged.exr")
    by_py = penumbra.merge(files, out=tmp_path / "merged-py.exr")
    assert np.array_equal(by_cli, by_py)
    assert np.array_equal(by_py, penumbra.merge(parts, spp=SPP))
    assert max_rel(by_py, whole) < 1e-5
    # A merged file is itself the part 0..spp: it merges alone.
    assert np.array_equal(penumbra.merge([tmp_path / "merged.exr"]), by_cli)


def test_parts_of_different_renders_do_not_merge(cli, tmp_path):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    cli("render", "cornell", "--res", "8x8", "--spp", "4", "--spp-range", "0..2", "-q", "-o", a)
    cli("render", "cornell", "--res", "8x8", "--spp", "4", "--seed", "1", "--spp-range", "2..4", "-q", "-o", b)
    with pytest.raises(ValueError, match="different renders"):
        penumbra.merge([a, b])


def test_a_plain_image_is_not_a_part(tmp_path, whole):
    penumbra.write_image(tmp_path / "plain.exr", whole)
    with pytest.raises(ValueError, match="not a part"):
        penumbra.merge([tmp_path / "plain.exr"])
