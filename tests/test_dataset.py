"""The sharded dataset generator and reader: determinism across restarts, workers and ranks,
config validation before any work, and metadata that reproduces each image."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
import torch

import roughsea_torch as rs
from roughsea_torch import dataset as D
from roughsea_torch.augmentation import SceneSampler, render_parameters
from roughsea_torch.dataset import (
    SeaShardDataset,
    build_sensor,
    finish,
    frame_render_parameters,
    generate,
    resolve_config,
    shard_name,
)

ROOT = Path(__file__).resolve().parents[1]
CFG = {
    "seed": 5,
    "num_images": 7,
    "shard_size": 3,
    "batch_size": 2,
    "camera": {"height": 20, "width": 28},
    "scene": {"atmospheres": ["tropical", "us_standard"], "wind_speed": [2.0, 12.0], "air_temperature": [285.0, 300.0]},
}


def _bytes(d: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(d.iterdir()) if p.name.startswith("shard_") or p.name == "manifest.json"}


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("uninterrupted")
    generate(CFG, out, progress=False)
    return out


def test_layout_and_manifest(reference):
    names = sorted(p.name for p in reference.iterdir())
    assert names == ["config.json", "manifest.json", "manifest_rank000.json"] + [shard_name(k) for k in range(3)]
    man = json.loads((reference / "manifest.json").read_text())
    assert man["complete"] and [e["images"] for e in man["shards"]] == [3, 3, 1]
    with np.load(reference / shard_name(2)) as z:
        assert z["images"].dtype == np.uint16 and z["images"].shape == (1, 20, 28)
        assert z["index"].tolist() == [6]
        assert int(z["images"].max()) <= 2**14 - 1


def test_killed_run_resumes_to_the_same_bytes(reference, tmp_path):
    code = (f"from roughsea_torch.dataset import generate; generate({CFG!r}, {str(tmp_path)!r}, progress=False, "
            "crash_after_shards=1)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 137, r.stderr  # died in the middle of writing its second shard
    assert (tmp_path / shard_name(0)).exists() and not (tmp_path / shard_name(1)).exists()
    assert list(tmp_path.glob(".shard_000001.npz.tmp*"))  # the half-written file it left
    assert not (tmp_path / "manifest.json").exists()
    generate(CFG, tmp_path, progress=False)  # the same command again
    assert not list(tmp_path.glob(".shard_*"))
    assert _bytes(tmp_path) == _bytes(reference)


def test_workers_and_ranks_write_the_same_bytes(reference, tmp_path):
    generate(CFG, tmp_path / "w2", workers=2, progress=False)
    assert _bytes(tmp_path / "w2") == _bytes(reference)
    ranks = tmp_path / "ranks"
    m1 = generate(CFG, ranks, rank=1, world_size=2, progress=False)
    assert [e["shard"] for e in m1["shards"]] == [1]  # disjoint parts: shard k to rank k mod 2
    with pytest.raises(RuntimeError, match="missing"):
        finish(ranks)
    generate(CFG, ranks, rank=0, world_size=2, progress=False)
    finish(ranks)
    assert _bytes(ranks) == _bytes(reference)


def test_torchrun(reference, tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text(
        'seed = 5\nnum_images = 7\nshard_size = 3\nbatch_size = 2\n[camera]\nheight = 20\nwidth = 28\n'
        '[scene]\natmospheres = ["tropical", "us_standard"]\nwind_speed = [2.0, 12.0]\nair_temperature = [285.0, 300.0]\n'
    )
    env = dict(os.environ, OMP_NUM_THREADS="1")
    # --standalone: a local rendezvous on a free port, so runs sharing a machine do not collide
    r = subprocess.run([sys.executable, "-m", "torch.distributed.run", "--standalone", "--nproc_per_node", "2",
                        str(ROOT / "pipelines" / "generate_dataset.py"), "--config", str(cfg), "--out", str(tmp_path / "o"),
                        "--no-progress"], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert {p.name for p in (tmp_path / "o").glob("manifest_rank*.json")} == {"manifest_rank000.json", "manifest_rank001.json"}
    assert _bytes(tmp_path / "o") == _bytes(reference)


def test_metadata_reproduces_each_image(reference):
    """Every parameter that made an image is in its metadata, the wave seed and time of its
    textured sea included (texture is on by default): re-rendering from it gives the same counts."""
    cfg = resolve_config(CFG)
    assert cfg["scene"]["texture"] is True and cfg["clip_length"] == 1
    sensor = build_sensor(cfg)
    ds = list(SeaShardDataset(reference))
    assert [m["index"] for _, m in ds] == list(range(7))
    with pytest.raises(TypeError, match="iterate"):  # a stream: ds[i] says so (it was torch's bare NotImplementedError)
        SeaShardDataset(reference)[0]
    atmospheres = ("tropical", "us_standard")
    textured = []
    for img, meta in ds[:3]:
        p = {k: torch.tensor([meta[k]], dtype=torch.float64) for k in SceneSampler().ranges}
        p["wave_seed"] = torch.tensor([meta["wave_seed"]])
        p["time_s"] = torch.tensor([meta["time_s"]], dtype=torch.float64)
        p["atmosphere"] = torch.tensor([atmospheres.index(meta["atmosphere"])])
        L = render_parameters(p, 20, 28, atmospheres)
        c = sensor(L, generator=torch.Generator().manual_seed(int(meta["noise_seed"])))
        assert torch.equal(c[0].round(), img)
        del p["wave_seed"]  # the expectation image of the same parameters
        flat = sensor(render_parameters(p, 20, 28, atmospheres), generator=torch.Generator().manual_seed(int(meta["noise_seed"])))
        textured.append(not torch.equal(flat[0].round(), img))
    # the texture is in the images (1.4° pixels from 10–100 m up resolve few waves: not in every one)
    assert any(textured)
    # the same parameters come from the sampler at (seed, index): nothing else made them
    s = SceneSampler(atmospheres=atmospheres, wind_speed=(2.0, 12.0), air_temperature=(285.0, 300.0),
                     texture=True).sample_indexed(5, [4])
    assert float(s["wind_speed"][0]) == ds[4][1]["wind_speed"]
    assert int(s["wave_seed"][0]) == ds[4][1]["wave_seed"] and float(s["time_s"][0]) == ds[4][1]["time_s"]
    assert 0.0 <= ds[4][1]["time_s"] < 3600.0


CLIPS = dict(CFG, num_images=2, shard_size=1, clip_length=3, frame_rate=5.0,
             scene=dict(CFG["scene"], pitch_deg=[-12.0, -6.0], altitude_m=[10.0, 30.0]),
             motion={"pitch_amplitude_deg": [1.0, 2.0], "roll_amplitude_deg": 3.0, "heave_period_s": [6.0, 8.0]})


def test_clips_reproduce_every_frame_from_metadata(tmp_path):
    """clip_length = 3 frames at 5 Hz: each item is a clip (T, 1, H, W); its metadata holds the
    per-frame time, pose and noise seed, and re-rendering any frame alone from them gives its
    counts; the frames are 0.2 s apart and the camera pitches between them."""
    generate(CLIPS, tmp_path, progress=False)
    with np.load(tmp_path / shard_name(1)) as z:
        assert z["images"].shape == (1, 3, 20, 28) and z["frame_time_s"].shape == (1, 3)
    cfg = resolve_config(CLIPS)
    sensor = build_sensor(cfg)
    atmospheres = ("tropical", "us_standard")
    items = list(SeaShardDataset(tmp_path))
    assert [m["index"] for _, m in items] == [0, 1]
    for clip, meta in items:
        assert clip.shape == (3, 1, 20, 28)
        torch.testing.assert_close(meta["frame_time_s"], meta["time_s"] + torch.tensor([0.0, 0.2, 0.4], dtype=torch.float64),
                                   rtol=0, atol=1e-9)
        assert 1.0 <= meta["pitch_amplitude_deg"] <= 2.0 and meta["roll_amplitude_deg"] == 3.0
        assert float(meta["frame_pitch_deg"].max() - meta["frame_pitch_deg"].min()) > 0.0
        assert len(set(meta["frame_noise_seed"].tolist())) == 3
        for t in range(3) if meta["index"] == 0 else [2]:
            p = frame_render_parameters(meta, t)
            p["atmosphere"] = torch.tensor([atmospheres.index(meta["atmosphere"])])
            L = render_parameters(p, 20, 28, atmospheres)
            c = sensor(L, generator=torch.Generator().manual_seed(int(p["noise_seed"])))
            assert torch.equal(c[0].round(), clip[t])
    # batches of clips collate to kornia's (B, T, C, H, W)
    x, m = next(iter(torch.utils.data.DataLoader(SeaShardDataset(tmp_path), batch_size=2)))
    assert x.shape == (2, 3, 1, 20, 28) and m["frame_time_s"].shape == (2, 3)
    with pytest.raises(ValueError, match="frame"):
        frame_render_parameters(meta, 3)


def test_texture_off_makes_expectation_images(tmp_path):
    """scene.texture = false: the shards hold no wave seed, and each image is the expectation
    image of its parameters (as before texture existed)."""
    cfg = dict(CFG, num_images=2, shard_size=2, scene=dict(CFG["scene"], texture=False))
    generate(cfg, tmp_path, progress=False)
    sensor = build_sensor(resolve_config(cfg))
    with np.load(tmp_path / shard_name(0)) as z:
        assert "wave_seed" not in z.files and "time_s" not in z.files
    for img, meta in SeaShardDataset(tmp_path):
        p = frame_render_parameters(meta)
        assert "wave_seed" not in p
        p["atmosphere"] = torch.tensor([("tropical", "us_standard").index(meta["atmosphere"])])
        c = sensor(render_parameters(p, 20, 28, ("tropical", "us_standard")),
                   generator=torch.Generator().manual_seed(int(meta["noise_seed"])))
        assert torch.equal(c[0].round(), img)


DAY = dict(CFG, seed=1, num_images=3, shard_size=3, batch_size=3,
           scene=dict(CFG["scene"], atmospheres=["tropical"], band="MWIR", daytime=0.5, sun_elevation_deg=[5.0, 20.0],
                      sun_azimuth_deg=[-20.0, 20.0]))


def test_day_metadata_reproduces_each_image(tmp_path):
    """scene.daytime > 0: each item's metadata holds is_day and its sun (elevation, zenith, world
    azimuth), the sampler's at (seed, index), ahead of the camera; re-rendering a day image and a
    night one (rendered in one batch) alone from it gives their counts bit for bit."""
    generate(DAY, tmp_path, progress=False)
    sensor = build_sensor(resolve_config(DAY))
    mwir, atmospheres = (3e-6, 5e-6), ("tropical",)
    items = list(SeaShardDataset(tmp_path))
    s = SceneSampler(atmospheres=atmospheres, wind_speed=(2.0, 12.0), air_temperature=(285.0, 300.0), texture=True,
                     band=mwir, daytime=0.5, sun_elevation_deg=(5.0, 20.0),
                     sun_azimuth_deg=(-20.0, 20.0)).sample_indexed(1, range(3))
    for _, meta in items:
        i = meta["index"]
        assert meta["is_day"] == bool(s["is_day"][i]) and meta["sun_azimuth_deg"] == float(s["sun_azimuth_deg"][i])
        assert meta["sun_zenith_deg"] == 90.0 - meta["sun_elevation_deg"] and 70.0 <= meta["sun_zenith_deg"] <= 85.0
        assert -20.0 <= meta["sun_azimuth_deg"] - meta["yaw_deg"] <= 20.0
    day = [(img, m) for img, m in items if m["is_day"]]
    night = [(img, m) for img, m in items if not m["is_day"]]
    assert day and night  # both kinds in the batch (seed 1: day, day, night)
    for img, meta in (day[0], night[0]):
        p = frame_render_parameters(meta)
        assert bool(p["is_day"]) == meta["is_day"]
        p["atmosphere"] = torch.tensor([0])
        c = sensor(render_parameters(p, 20, 28, atmospheres, band=mwir),
                   generator=torch.Generator().manual_seed(int(meta["noise_seed"])))
        assert torch.equal(c[0].round(), img)


def test_render_table_reaches_the_shards_and_is_recorded(tmp_path):
    """config ``render`` (TableSize fields): MWIR glitter by day. The day image's counts equal a
    re-render from its metadata with ``TableSize(glitter=True)`` bit for bit, differ from the same
    item without glitter, and the resolved config holds the setting; a bad value names its key."""
    cfg = dict(DAY, render={"glitter": True})
    generate(cfg, tmp_path, progress=False)
    assert json.loads((tmp_path / "config.json").read_text())["config"]["render"]["glitter"] is True
    sensor = build_sensor(resolve_config(cfg))
    img, meta = next((i, m) for i, m in SeaShardDataset(tmp_path) if m["is_day"])
    p = frame_render_parameters(meta)
    p["atmosphere"] = torch.tensor([0])
    g = torch.Generator
    seed = int(meta["noise_seed"])
    glitter = sensor(render_parameters(p, 20, 28, ("tropical",), band=(3e-6, 5e-6), table=rs.TableSize(glitter=True)),
                     generator=g().manual_seed(seed))
    plain = sensor(render_parameters(p, 20, 28, ("tropical",), band=(3e-6, 5e-6)), generator=g().manual_seed(seed))
    assert torch.equal(glitter[0].round(), img)
    assert not torch.equal(plain[0].round(), img)
    with pytest.raises(ValueError, match="render.texture_hit"):
        resolve_config(dict(CFG, render={"texture_hit": "last"}))
    with pytest.raises(ValueError, match="render.glitter"):
        resolve_config(dict(CFG, render={"glitter": "yes"}))
    with pytest.raises(ValueError, match="render.speed"):
        resolve_config(dict(CFG, render={"speed": 1}))


def test_reader_splits_over_workers_and_converts_to_radiance(reference):
    ds = SeaShardDataset(reference, radiance=True)
    assert len(ds) == 7
    counts = {m["index"]: x for x, m in SeaShardDataset(reference)}
    adc = build_sensor(resolve_config(CFG)).counts
    seen = []
    for x, m in torch.utils.data.DataLoader(ds, batch_size=2, num_workers=2):
        assert x.shape[1:] == (1, 20, 28)
        for xi, i in zip(x, m["index"].tolist()):
            # the radiance maps back onto the stored counts (the ADC's own inverse)
            torch.testing.assert_close((xi.double() * adc.gain + adc.offset), counts[i].double(), rtol=0, atol=1e-2)
        seen += m["index"].tolist()
    assert sorted(seen) == list(range(7))
    half = [m["index"] for _, m in SeaShardDataset(reference, rank=1, world_size=2)]
    assert half == [3, 4, 5]
    sh = SeaShardDataset(reference, shuffle=True, seed=1)
    e0 = [m["index"] for _, m in sh]
    sh.set_epoch(1)
    e1 = [m["index"] for _, m in sh]
    assert sorted(e0) == sorted(e1) == list(range(7)) and e0 != e1
    # images are shuffled within a shard too, not only the shard order
    first = {0: [i for i in e0 if i < 3], 1: [i for i in e1 if i < 3]}
    assert first[0] != [0, 1, 2] or first[1] != [0, 1, 2]


@pytest.mark.parametrize(
    "patch, key",
    [
        ({"num_image": 3}, "num_image"),
        ({"scene": {"wind_sped": [1, 2]}}, "scene.wind_sped"),
        ({"scene": {"pitch_deg": [-1.0, -8.0]}}, "pitch_deg"),
        ({"scene": {"altitude_m": [-10.0, 20.0]}}, "altitude_m"),
        ({"scene": {"sea_temperature": []}}, "sea_temperature"),
        ({"scene": {"atmospheres": []}}, "atmospheres"),
        ({"camera": {"height": 0}}, "camera.height"),
        ({"sensor": {"noise": {"netd": 0.05}}}, "sensor.noise.netd"),
        ({"sensor": {"noise": {"netd_k": -1.0}}}, "netd_k"),
        ({"sensor": {"counts": False}}, "sensor.counts"),
        ({"sensor": {"counts": {"bits": 20}}}, "sensor.counts.bits"),
        ({"sensor": {"lens": {}}}, "sensor.lens"),
        ({"scene": {"texture": "yes"}}, "scene.texture"),
        ({"scene": {"time_s": [-5.0, 10.0]}}, "scene.time_s"),
        ({"scene": {"daytime": 1.5}}, "scene.daytime"),
        ({"scene": {"sun_elevation_deg": [10.0, 95.0]}}, "scene.sun_elevation_deg"),
        ({"scene": {"sun_azimuth_deg": [30.0, -30.0]}}, "scene.sun_azimuth_deg"),
        ({"scene": {"sun_azimuth_relative_to_yaw": 1}}, "scene.sun_azimuth_relative_to_yaw"),
        ({"clip_length": 0}, "clip_length"),
        ({"frame_rate": 0.0}, "frame_rate"),
        ({"motion": {"pitch_amp": 1.0}}, "motion.pitch_amp"),
        ({"motion": {"roll_period_s": [3.0, 1.0]}}, "motion.roll_period_s"),
        ({"clip_length": 4, "motion": {"heave_amplitude_m": 9.5}, "scene": {"altitude_m": [10.0, 20.0]}},
         "motion.heave_amplitude_m"),
    ],
)
def test_invalid_configs_fail_before_any_work(patch, key, tmp_path):
    cfg = json.loads(json.dumps(CFG))
    for k, v in patch.items():
        if isinstance(v, dict) and isinstance(cfg.get(k), dict):
            cfg[k].update(v)
        else:
            cfg[k] = v
    with pytest.raises(ValueError, match=key.replace(".", r"\.")):
        generate(cfg, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("altitude", [[0.5, 20.0], [100.0, 8000.0]])
def test_altitudes_outside_the_path_tables_fail_before_any_work(altitude, tmp_path):
    """With the path on (the default), scene.altitude_m must stay within the path tables' 2 m – 5 km;
    with path = false the sampler's wider 0.5 m – 20 km is allowed."""
    cfg = dict(CFG, scene=dict(CFG["scene"], altitude_m=altitude))
    with pytest.raises(ValueError, match=r"scene\.altitude_m.*\[2, 5000\] m"):
        generate(cfg, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()
    off = resolve_config(dict(cfg, scene=dict(cfg["scene"], path=False)))
    assert off["scene"]["altitude_m"] == altitude and off["scene"]["path"] is False


def test_resume_refuses_another_config(reference, tmp_path):
    out = tmp_path / "o"
    generate(dict(CFG, num_images=2), out, progress=False)
    with pytest.raises(ValueError, match="another config"):
        generate(dict(CFG, num_images=3), out, progress=False)


def test_cli_reports_a_bad_key_without_work(tmp_path):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("num_images = 2\n[scene]\nwind_speed = [5.0, 1.0]\n")
    r = subprocess.run([sys.executable, str(ROOT / "pipelines" / "generate_dataset.py"), "--config", str(cfg),
                        "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert r.returncode == 2 and "wind_speed" in r.stderr and "inverted" in r.stderr
    assert not (tmp_path / "o").exists()


def test_a_sensor_stage_left_out(tmp_path):
    """``noise = false`` leaves the temporal noise out: images with the same parameters and fixed
    pattern are then identical whatever the noise seed, and differ from the noisy run."""
    cfg = dict(CFG, num_images=2, shard_size=2, sensor={"noise": False})
    generate(cfg, tmp_path / "quiet", progress=False)
    with np.load(tmp_path / "quiet" / shard_name(0)) as z:
        quiet = z["images"].astype(np.int64)
    assert resolve_config(cfg)["sensor"]["noise"] is False
    s = build_sensor(resolve_config(cfg))
    assert s.noise is None and s.blur is not None
    with np.load(tmp_path / "quiet" / shard_name(0)) as z:
        p = {k: torch.from_numpy(np.asarray(z[k], dtype=np.float64)) for k in [*SceneSampler().ranges, "time_s"]}
        p["wave_seed"] = torch.from_numpy(z["wave_seed"])
        p["atmosphere"] = torch.tensor([("tropical", "us_standard").index(str(a)) for a in z["atmosphere"]])
    L = render_parameters(p, 20, 28, ("tropical", "us_standard"))
    a = torch.cat([s(L[i : i + 1], generator=torch.Generator().manual_seed(1)) for i in range(2)]).round()
    b = torch.cat([s(L[i : i + 1], generator=torch.Generator().manual_seed(2)) for i in range(2)]).round()
    assert torch.equal(a, b) and np.array_equal(a[:, 0].numpy().astype(np.int64), quiet)


def test_foam_off_in_the_config_reaches_the_shards(tmp_path):
    """scene.foam = false makes seas without whitecaps: a strong-wind image re-renders from its
    metadata with render_parameters(..., foam=False), not with the default whitecaps; a bad value is
    a config error naming scene.foam."""
    cfg = dict(CFG, num_images=1, shard_size=1, scene=dict(CFG["scene"], wind_speed=[15.0, 15.0], foam=False))
    generate(cfg, tmp_path, progress=False)
    resolved = resolve_config(cfg)
    assert resolved["scene"]["foam"] is False
    sensor = build_sensor(resolved)
    (img, meta), = list(SeaShardDataset(tmp_path))
    atmospheres = ("tropical", "us_standard")
    p = frame_render_parameters(meta)
    p["atmosphere"] = torch.tensor([atmospheres.index(meta["atmosphere"])])

    def counts(**kw):
        L = render_parameters(p, 20, 28, atmospheres, **kw)
        return sensor(L, generator=torch.Generator().manual_seed(int(meta["noise_seed"])))[0].round()

    assert torch.equal(counts(foam=False), img)
    assert not torch.equal(counts(), img)
    with pytest.raises(ValueError, match="scene.foam"):
        resolve_config(dict(CFG, scene=dict(CFG["scene"], foam="maybe")))
    with pytest.raises(ValueError, match="scene.foam"):
        resolve_config(dict(CFG, scene=dict(CFG["scene"], foam=1.5)))
    with pytest.raises(ValueError, match="scene.foam: one setting for every image"):
        resolve_config(dict(CFG, scene=dict(CFG["scene"], foam=[0.1, 0.2])))


def test_frame_render_parameters_docstring_matches_its_result():
    """The docstring promised an "atmosphere_name" key the result never had."""
    meta = {name: 1.0 for name, *_r in D.SCENE_FIELDS}
    meta.update(atmosphere="midlatitude_summer", noise_seed=np.int64(9), wave_seed=np.int64(4), time_s=2.5)
    p = D.frame_render_parameters(meta)
    doc = D.frame_render_parameters.__doc__
    assert "atmosphere" not in p and "atmosphere_name" not in doc
    assert 'meta["atmosphere"]' in doc
    for key in set(p) - {name for name, *_r in D.SCENE_FIELDS}:
        assert f"``{key}``" in doc, key


def test_dataset_workers_warnings_point_at_the_callers_line():
    """A warning raised while a worker process renders a shard (here: the light wind's resolved slopes
    scaled to Cox–Munk) reaches the caller of generate at the caller's line; it pointed into
    multiprocessing, in the worker."""
    from roughsea_torch.dataset import generate

    cfg = {"num_images": 2, "shard_size": 1, "batch_size": 1, "camera": {"height": 12, "width": 16},
           "scene": {"wind_speed": [0.4, 0.5], "altitude_m": [2.0, 3.0], "pitch_deg": [-60.0, -50.0],
                     "hfov_deg": [2.0, 3.0], "daytime": 0.0}, "sensor": {}}
    with tempfile.TemporaryDirectory() as d, warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        generate(cfg, d, workers=1, progress=False)
    scaled = [w for w in caught if "scaled down" in str(w.message)]
    assert scaled and all(w.filename == __file__ for w in scaled)



def test_air_sea_difference_reaches_the_metadata(tmp_path):
    """scene.air_sea_difference: config.json records the range, each item's metadata its air (its
    sea plus a difference within the range) and the difference T_air − T_sea; re-rendering from the
    metadata gives the counts, also from metadata without the record (shards written before it)."""
    cfg = {"seed": 2, "num_images": 3, "shard_size": 3, "batch_size": 3, "camera": {"height": 10, "width": 12},
           "scene": {"texture": False, "sea_temperature": [285.0, 302.0], "air_sea_difference": [-3.0, 1.0]}}
    generate(cfg, tmp_path, progress=False)
    assert json.loads((tmp_path / "config.json").read_text())["config"]["scene"]["air_sea_difference"] == [-3.0, 1.0]
    sensor = build_sensor(resolve_config(cfg))
    for img, meta in SeaShardDataset(tmp_path):
        d = meta["air_temperature"] - meta["sea_temperature"]
        assert -3.0 - 1e-9 <= d <= 1.0 + 1e-9 and abs(meta["air_sea_difference"] - d) < 1e-9
        old = {k: v for k, v in meta.items() if k != "air_sea_difference"}
        for m in (meta, old):
            p = frame_render_parameters(m)
            p["atmosphere"] = torch.tensor([0])
            c = sensor(render_parameters(p, 10, 12, ("midlatitude_summer",)),
                       generator=torch.Generator().manual_seed(int(meta["noise_seed"])))
            assert torch.equal(c[0].round(), img)
