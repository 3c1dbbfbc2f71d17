"""Chunks on worker threads (roughsea_torch._parallel): the same numbers whatever the thread
count, the caller's thread settings and autograd mode respected."""

from __future__ import annotations

import sys
import threading

import pytest
import torch

import roughsea_torch as rs

from conftest import make_cams, make_scene


def _scene(wind):
    return rs.SeaScene(wind_speed=wind, wind_direction=torch.tensor([0.1, 0.9, 2.0, -1.0]),
                       sea_temperature=torch.tensor([285.0, 290.0, 295.0, 300.0]))


def _cams():
    return make_cams(altitude_m=torch.tensor([10.0, 20.0, 50.0, 200.0]), pitch_deg=torch.tensor([-2.0, -4.0, -8.0, -1.0]))


def test_images_do_not_depend_on_the_thread_count(two_threads):
    wind = torch.tensor([3.0, 6.0, 9.0, 12.0])
    two = rs.render(_cams(), _scene(wind), chunk=1)
    torch.set_num_threads(1)
    one = rs.render(_cams(), _scene(wind), chunk=1)
    assert torch.equal(one, two)


def test_caller_and_new_threads_keep_their_thread_count(two_threads):
    rs.render(_cams(), _scene(torch.tensor([3.0, 6.0, 9.0, 12.0])), chunk=1)
    assert torch.get_num_threads() == 2
    seen = []
    t = threading.Thread(target=lambda: seen.append(torch.get_num_threads()))
    t.start()
    t.join()
    assert seen == [2]  # workers restore torch's default for new threads


def test_autograd_mode_reaches_the_workers(two_threads):
    wind = torch.tensor([3.0, 6.0, 9.0, 12.0], dtype=torch.float64, requires_grad=True)
    from roughsea_torch._parallel import map_chunks

    with torch.no_grad():  # no graph is recorded in the workers either
        assert map_chunks(lambda _: torch.is_grad_enabled(), [0, 1, 2], "cpu") == [False] * 3
    assert map_chunks(lambda _: torch.is_grad_enabled(), [0, 1, 2], "cpu") == [True] * 3
    (g2,) = torch.autograd.grad(rs.render(_cams(), _scene(wind), chunk=1).sum(), wind)
    torch.set_num_threads(1)
    (g1,) = torch.autograd.grad(rs.render(_cams(), _scene(wind), chunk=1).sum(), wind)
    # the backward pass runs on the caller's threads, whose reductions split by their count: one ulp
    # (1.8e-16 relative) between 1 and 2 threads on an Intel Xeon, none on an AMD EPYC
    assert torch.allclose(g1, g2, rtol=1e-14, atol=0.0) and bool((g1 != 0).all())


def test_sensor_runs_on_one_thread_and_restores_the_setting():
    """SensorModel runs its chain with one intra-op thread (roughsea_torch._parallel.one_thread): the
    caller's thread count is restored afterwards, even when a stage raises, and the result equals the
    one-thread result bit for bit."""
    sensor = rs.SensorModel.typical_lwir()
    x = rs.band_radiance(torch.full((3, 1, 16, 20), 295.0) + torch.rand(3, 1, 16, 20, generator=torch.Generator().manual_seed(1)))
    gens = lambda: [torch.Generator().manual_seed(i) for i in range(3)]  # noqa: E731
    before = torch.get_num_threads()
    try:
        torch.set_num_threads(1)
        one = sensor(x, generator=gens())
        torch.set_num_threads(2)
        two = sensor(x, generator=gens())
        assert torch.get_num_threads() == 2
        assert torch.equal(one, two)
        class Boom(torch.nn.Module):
            def forward(self, image):
                assert torch.get_num_threads() == 1  # the chain runs on one thread
                raise RuntimeError("boom")

        with pytest.raises(RuntimeError, match="boom"):
            rs.SensorModel(blur=Boom())(x)
        assert torch.get_num_threads() == 2
    finally:
        torch.set_num_threads(before)


def test_a_lone_chunk_runs_on_one_thread_more_chunks_on_the_workers(two_threads, monkeypatch):
    """With 2 threads, render() spreads two chunks over the worker threads (one intra-op thread each),
    runs a render of one chunk, its preparation included, on the calling thread with one intra-op
    thread (on shared cores a second one slows its many small operations down), and restores the
    caller's setting."""
    from roughsea_torch import _parallel as P

    seen = []
    map_chunks = P.map_chunks

    def spy_map(fn, items, device):
        def wrapped(x):
            seen.append((threading.current_thread().name, torch.get_num_threads()))
            return fn(x)
        return map_chunks(wrapped, items, device)

    setup = []
    resolved = rs.SeaScene.resolved

    def spy_setup(self, *a, **k):
        setup.append(torch.get_num_threads())
        return resolved(self, *a, **k)

    monkeypatch.setattr(sys.modules["roughsea_torch.renderer.table"], "map_chunks", spy_map)
    monkeypatch.setattr(rs.SeaScene, "resolved", spy_setup)
    wind = torch.tensor([3.0, 6.0, 9.0, 12.0])
    two = rs.render(_cams(), _scene(wind), chunk=2)
    assert len(seen) == 2 and all(name.startswith("roughsea") and n == 1 for name, n in seen)
    assert setup == [2] and torch.get_num_threads() == 2  # the preparation at the caller's setting
    seen.clear()
    setup.clear()
    one = rs.render(_cams(), _scene(wind), chunk=4)  # one chunk: all of it on one intra-op thread
    assert seen == [(threading.current_thread().name, 1)] and setup == [1] and torch.get_num_threads() == 2
    assert torch.equal(one, two)


def test_augmentation_builds_scenes_and_composites_on_one_thread(two_threads, monkeypatch):
    """RandomSeaBackground and RandomSeaClip build their scenes and cameras and composite (with the
    sensor) on one intra-op thread, and restore the caller's setting (also when a stage raises)."""
    from roughsea_torch import augmentation as A
    from roughsea_torch import parameter_render as R

    seen = {"scene": [], "finish": []}
    finish, scene_init = A.RandomSeaBase._finish, R.SeaScene.__init__

    def spy_finish(self, *a, **k):
        seen["finish"].append(torch.get_num_threads())
        if len(seen["finish"]) > 1:
            raise RuntimeError("boom")
        return finish(self, *a, **k)

    def spy_scene(self, *a, **k):
        seen["scene"].append(torch.get_num_threads())
        return scene_init(self, *a, **k)

    seen["camera"] = []
    make_camera = R.make_camera

    def spy_camera(*a, **k):
        seen["camera"].append(torch.get_num_threads())
        return make_camera(*a, **k)

    monkeypatch.setattr(A.RandomSeaBase, "_finish", spy_finish)
    monkeypatch.setattr(R.SeaScene, "__init__", spy_scene)
    monkeypatch.setattr(R, "make_camera", spy_camera)
    aug = rs.RandomSeaBackground(texture=False, output="brightness_temperature")
    aug(torch.zeros(2, 1, 12, 16), generator=torch.Generator().manual_seed(0))
    assert seen["finish"] == [1] and seen["scene"] and set(seen["scene"]) == {1} and set(seen["camera"]) == {1}
    assert torch.get_num_threads() == 2
    with pytest.raises(RuntimeError, match="boom"):
        aug(torch.zeros(2, 1, 12, 16))
    assert seen["finish"] == [1, 1] and torch.get_num_threads() == 2
    # the clip augmentation alike (frame cameras, compositing)
    seen["finish"].clear()
    seen["camera"].clear()
    rs.RandomSeaClip(texture=False, frame_rate=5.0, output="brightness_temperature")(
        torch.zeros(1, 2, 1, 12, 16), generator=torch.Generator().manual_seed(1))
    assert seen["finish"] == [1] and set(seen["camera"]) == {1} and len(seen["camera"]) == 2
    assert torch.get_num_threads() == 2


def test_atmosphere_groups_render_on_the_workers_and_match_one_thread(two_threads, monkeypatch):
    """Several renders of one chunk each (images in three atmosphere groups) run side by side on the
    worker threads, with the same images as on one thread (bitwise); with a gradient wanted they
    run in turn on the calling thread, and the gradient matches one thread's."""
    from roughsea_torch import augmentation as A
    from roughsea_torch import parameter_render as R

    s = rs.SceneSampler(atmospheres=["midlatitude_summer", "tropical", "us_standard"])
    p = s.sample(6, torch.Generator().manual_seed(3))
    p["atmosphere"] = torch.tensor([0, 1, 2, 0, 1, 2])
    where = []
    render = R.render

    def spy(*a, **k):
        where.append(threading.current_thread().name)
        return render(*a, **k)

    monkeypatch.setattr(R, "render", spy)
    two = A.render_parameters(p, 12, 16, s.atmospheres, dtype=torch.float64)
    assert len(where) == 3 and all(name.startswith("roughsea") for name in where)
    torch.set_num_threads(1)
    one = A.render_parameters(p, 12, 16, s.atmospheres, dtype=torch.float64)
    assert torch.equal(one, two)
    torch.set_num_threads(2)
    where.clear()
    wind = p["wind_speed"].clone().double().requires_grad_(True)
    (g2,) = torch.autograd.grad(A.render_parameters(dict(p, wind_speed=wind), 12, 16, s.atmospheres,
                                                    dtype=torch.float64).sum(), wind)
    assert where == [threading.current_thread().name] * 3
    torch.set_num_threads(1)
    (g1,) = torch.autograd.grad(A.render_parameters(dict(p, wind_speed=wind), 12, 16, s.atmospheres,
                                                    dtype=torch.float64).sum(), wind)
    assert torch.equal(g1, g2) and bool((g1 != 0).all())
    # a group of 5 images (two chunks: the render spreads them itself) or textured groups (a chunk an
    # image): the renders run in turn on the calling thread
    torch.set_num_threads(2)
    for atm, extra in (([0, 0, 0, 0, 0, 1], {}), ([0, 1, 2, 0, 1, 2], dict(wave_seed=torch.arange(6)))):
        where.clear()
        A.render_parameters(dict(p, atmosphere=torch.tensor(atm), **extra), 12, 16, s.atmospheres)
        assert where == [threading.current_thread().name] * len(set(atm))


def test_map_chunks_lone_chunk_and_autocast(two_threads):
    """map_chunks runs a lone chunk on the calling thread with one intra-op thread, and the workers
    take the caller's CPU autocast: a render under bfloat16 autocast is the same on 1 and 2 threads
    (it differed by 0.28 W m-2 sr-1 before the workers took it)."""
    from roughsea_torch._parallel import map_chunks

    def probe(_):
        return threading.current_thread().name, torch.get_num_threads(), torch.is_autocast_enabled("cpu")

    assert map_chunks(probe, [0], "cpu") == [(threading.current_thread().name, 1, False)]
    assert torch.get_num_threads() == 2
    with torch.autocast("cpu", dtype=torch.bfloat16):
        on_workers = map_chunks(probe, [0, 1], "cpu")
        assert all(name.startswith("roughsea") and n == 1 and ac for name, n, ac in on_workers)
        cams = make_cams(altitude_m=torch.tensor([10.0, 20.0, 50.0, 200.0]), pitch_deg=torch.tensor([-2.0, -4.0, -8.0, -1.0]),
                         dtype=torch.float32)
        two = rs.render(cams, _scene(torch.tensor([3.0, 6.0, 9.0, 12.0])), chunk=2)
        torch.set_num_threads(1)
        one = rs.render(cams, _scene(torch.tensor([3.0, 6.0, 9.0, 12.0])), chunk=2)
    plain = rs.render(cams, _scene(torch.tensor([3.0, 6.0, 9.0, 12.0])), chunk=2)
    assert torch.equal(one, two) and not torch.equal(one, plain)  # (autocast does change the numbers)


def test_textured_render_of_two_images_uses_the_workers(two_threads, monkeypatch):
    """A textured scene renders a chunk an image: two images are two chunks, on the workers (the
    one-chunk path of render() must count the chunks of the scene's kind)."""
    from roughsea_torch import _parallel as P

    names = []
    map_chunks = P.map_chunks

    def spy_map(fn, items, device):
        def wrapped(x):
            names.append(threading.current_thread().name)
            return fn(x)
        return map_chunks(wrapped, items, device)

    monkeypatch.setattr(sys.modules["roughsea_torch.renderer.table"], "map_chunks", spy_map)
    cams = make_cams(16, 20, pitch_deg=-6.0, batch_size=2, dtype=torch.float32)
    rs.render(cams, make_scene(seed=[1, 2]))
    assert len(names) >= 2 and all(n.startswith("roughsea") for n in names)


@pytest.mark.skipif(not torch.cuda.is_available(), reason="needs CUDA")
def test_default_device_reaches_the_renders():
    """render_parameters(device=None) under torch.set_default_device("cuda") renders on CUDA (the
    default device is per thread: it is resolved before any render runs elsewhere)."""
    s = rs.SceneSampler(atmospheres=["midlatitude_summer", "tropical"])
    p = s.sample(4, torch.Generator().manual_seed(3))
    p["atmosphere"] = torch.tensor([0, 1, 0, 1])
    from roughsea_torch.augmentation import render_parameters

    torch.set_default_device("cuda")
    try:
        img = render_parameters(p, 12, 16, s.atmospheres)
    finally:
        torch.set_default_device("cpu")
    assert img.device.type == "cuda"
