"""Scene.render against the CLI, argument errors, loading errors and warnings."""

import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import warnings

import numpy as np
import pytest

import penumbra

SMALL = dict(res=(48, 32), spp=8)


@pytest.fixture(scope="module")
def cornell():
    return penumbra.load("cornell")


@pytest.mark.parametrize(
    "settings",
    [
        {},
        dict(strategy="bsdf", pattern="sobol", light_selection="power", seed=7, threads=1),
        dict(strategy="light-area", shadow_rays=3, mis="balance", pattern="random", seed=3),
        dict(hide_emitters=True, seed=2),
    ],
)
def test_array_equals_cli_image_bit_for_bit(cli, tmp_path, cornell, settings):
    kw = dict(SMALL, **settings)
    img = cornell.render(**kw)
    assert img.dtype == np.float32 and img.shape == (32, 48, 3)
    flags = ["--res", "48x32", "--spp", "8", "-q", "-o", tmp_path / "cli.exr"]
    for k, v in settings.items():
        flag = f"--{k.replace('_', '-')}"
        # A boolean keyword is a bare CLI flag.
        flags += [flag] if v is True else [flag, v]
    cli("render", "cornell", *flags)
    ref = penumbra.read_image(tmp_path / "cli.exr")
    assert np.array_equal(img, ref), f"max |diff| {np.abs(img - ref).max()}"
    assert img.mean() > 0.01


def test_thread_count_does_not_change_the_image(cornell):
    assert np.array_equal(cornell.render(threads=1, **SMALL), cornell.render(threads=2, **SMALL))


@pytest.mark.parametrize(
    "arg, choices",
    [
        ("strategy", "bsdf, light-area, light-solid-angle, mis"),
        ("pattern", "fixed, random, grid, stratified, lhs, sobol"),
        ("light_selection", "uniform, power, spatial, adaptive, online, wald, bvh, exhaustive"),
        ("mis", "power or balance"),
        ("integrator", "direct"),
        ("mis_light", "solid-angle, area"),
        ("bsdf_sampling", "importance, cosine or uniform"),
    ],
)
def test_bad_choice_raises_value_error_listing_the_valid_ones(cornell, arg, choices):
    with pytest.raises(ValueError) as e:
        cornell.render(**{arg: "nonsense"}, **SMALL)
    assert arg in str(e.value) and "nonsense" in str(e.value) and choices in str(e.value)


@pytest.mark.parametrize(
    "kw, text",
    [
        (dict(spp=0), "at least 1"),
        (dict(res="12"), "WxH"),
        (dict(res=(0, 8)), "between 1 and 65536"),
        (dict(spp=8, spp_range=(4, 9)), "within 0..8"),
        (dict(spp_range=(3, 3)), "non-empty"),
        (dict(integrator="direct", max_depth=3), "depth"),
    ],
)
def test_bad_values_raise_value_error(cornell, kw, text):
    args = dict(res=(8, 8), spp=8)
    args.update(kw)
    with pytest.raises(ValueError, match=text):
        cornell.render(**args)


def test_missing_scene_file_raises_file_not_found_naming_it(tmp_path):
    missing = tmp_path / "no-such-scene.pbrt"
    with pytest.raises(FileNotFoundError) as e:
        penumbra.load(missing)
    assert e.value.filename == str(missing) and "no-such-scene.pbrt" in str(e.value)


def test_missing_include_raises_scene_error_naming_both_files(tmp_path):
    scene = tmp_path / "s.pbrt"
    scene.write_text('Include "gone.pbrt"\nWorldBegin\n')
    with pytest.raises(penumbra.SceneError) as e:
        penumbra.load(scene)
    assert "s.pbrt:1" in str(e.value) and "gone.pbrt" in str(e.value)


def test_bad_scene_file_raises_scene_error_with_file_and_line(tmp_path):
    scene = tmp_path / "broken.pbrt"
    scene.write_text('WorldBegin\nShape "sphere" "float radius" [ 1 ]\nFoo 3\n')
    with pytest.raises(penumbra.SceneError) as e:
        penumbra.load(scene)
    assert isinstance(e.value, ValueError)
    assert "broken.pbrt:3:1: unknown directive 'Foo'" in str(e.value), str(e.value)


def test_loader_warnings_are_python_warnings(tmp_path):
    obj = tmp_path / "m.obj"
    # One good triangle, one of zero area (dropped with a warning naming the file).
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 2\nf 1 2 3\nf 4 4 4\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = penumbra.load(obj)
    msgs = [str(w.message) for w in caught if issubclass(w.category, penumbra.SceneWarning)]
    assert msgs and all("m.obj" in m for m in msgs), msgs
    assert scene.warnings


def test_unknown_load_knob_is_a_type_error_listing_knobs():
    with pytest.raises(TypeError, match="light_count"):
        penumbra.load("cornell", lights=4)


def test_gil_is_released_while_rendering(cornell):
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        start = len(ticks)
        cornell.render(res=(128, 128), spp=64)
        during = len(ticks) - start
    finally:
        stop.set()
        t.join()
    assert during > 5, f"the counting thread ran {during} times during the render"


def test_ctrl_c_interrupts_a_render_cleanly():
    code = textwrap.dedent(
        """
        import sys, time, penumbra
        s = penumbra.load("cornell")
        print("ready", flush=True)
        t = time.time()
        try:
            s.render(spp=4096, res=(512, 512))
            print("finished", flush=True)
        except KeyboardInterrupt:
            print(f"interrupted after {time.time() - t:.2f}s", flush=True)
        """
    )
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=30)
    assert out.startswith("interrupted after"), out
    assert float(out.split()[2].rstrip("s")) < 5.0, out
    assert p.returncode == 0


def test_image_files_round_trip(tmp_path, cornell):
    img = cornell.render(**SMALL)
    for ext in ("exr", "pfm"):
        penumbra.write_image(tmp_path / f"x.{ext}", img)
        assert np.array_equal(penumbra.read_image(tmp_path / f"x.{ext}"), img)
    with pytest.raises(FileNotFoundError, match="missing.exr"):
        penumbra.read_image(tmp_path / "missing.exr")


def test_compare_gives_the_cli_numbers(cli, tmp_path, cornell):
    a = cornell.render(seed=1, **SMALL)
    b = cornell.render(seed=2, spp=64, res=SMALL["res"])
    penumbra.write_image(tmp_path / "a.exr", a)
    penumbra.write_image(tmp_path / "b.exr", b)
    got = penumbra.compare(a, tmp_path / "b.exr")
    out = cli("compare", tmp_path / "a.exr", tmp_path / "b.exr").stdout.split()
    printed = dict(zip(out[0::2], out[1::2]))
    assert float(f"{got['mse']:.4e}") == float(printed["MSE"])
    assert float(f"{got['rel_mse']:.4e}") == float(printed["relMSE"])
    assert float(f"{got['mae']:.4e}") == float(printed["MAE"])
    assert got["mse"] > 0
    with pytest.raises(ValueError, match="sizes differ"):
        penumbra.compare(a, b[:8])
