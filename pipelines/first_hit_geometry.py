"""Where the sweep's visible surface sits against the ray tracer's first hits (issue 22).

For the comparison pipeline's case (48×64 px over 12°, pitch −6°, 15 m mast, LWIR, LOWTRAN midlatitude
summer, sea at 290 K, seed 11, t = 3 s, flat Earth as the pipeline renders it) and a band of rows, it
builds, per pixel, from one node-value function T(θ̂, φ̂, a) — the sweep's node value: the model on the
unresolved statistics at the sweep's default sample footprint F_s about the along-view slope a resolved
at F_s (``clutter.unresolved_statistics`` → ``expectation.apparent_radiance``, tabulated in θ̂, φ̂, a) —

- (a) the ray tracer's image: the mean over each pixel's jittered rays of the ray tracer's radiance at
  its first hit on the k ≤ 64 rad/m surface (``raytrace.trace_first_hits``; the model about the traced
  slope on Σ_CM − Σ_traced, as ``raytraced_image`` in ``mode="two_scale"``);
- (b) the same rays with T at the hit (a read at F_s there): the ray tracer's geometry, the sweep's
  node values;
- (c) sweeps (``hits.sweep_layout`` → ``sweep_envelope`` → ``visible_samples`` → ``visible_average``,
  called as ``TextureTable._pixels_swept`` calls them, one track per pixel width) whose visibility
  (the running minimum of the depressions) is computed on an elevation chosen per variant, with the
  samples optionally n× denser, while each sample's value stays T at the slope resolved at F_s:
  ``n1:Fs`` is the renderer's default; ``nN:Fs/N`` denser samples with the elevation filtered at the
  finer sample footprint; ``nN:Fs`` denser samples, elevation still at F_s (control); ``nN:k64`` the
  ray tracer's own surface (``raytrace.TracedSurface``, k ≤ 64 rad/m); a trailing ``:i`` (``n4:Fs/4:i``)
  reads a only at the default samples and interpolates it in range to the denser ones.

Per 8-row bin it prints where the seen surface lies (mean ground range, share of the seen surface on
faces tilted towards the camera, mean along-view slope at F_s and on the k ≤ 64 surface) for the
rays' hits and for each sweep, and the regression gain and correlation of each image on (a) and on (b)
per pixel and after 4×4 blocks (the ray tracer's sampling variance removed). ``--cost`` times the
sweep's elevation reads, envelope and visible-sample count of each variant on a 256×320 camera.

Usage:
    python pipelines/first_hit_geometry.py [--wind 5] [--direction upwind] [--rows 8 40] [--rays 32]
        [--variants n1:Fs n2:Fs/2 n4:Fs/4 n4:Fs/4:i n4:Fs n8:k64] [--render x9 default]
    python pipelines/first_hit_geometry.py --cost [--variants ...]      # the sweep's reads and time at 256×320
    python pipelines/first_hit_geometry.py --time-render x9 default    # one 256×320 render per TableSize setting
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from kornia.geometry.camera import PinholeCamera

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import roughsea_torch as rs  # noqa: E402
from roughsea_torch import raytrace as rt  # noqa: E402
from roughsea_torch.atmosphere import load_sky  # noqa: E402
from roughsea_torch.clutter import footprint, unresolved_statistics  # noqa: E402
from roughsea_torch.expectation import apparent_radiance  # noqa: E402
from roughsea_torch.optics import band_refractive_index  # noqa: E402
from roughsea_torch.quadrature import Quadrature  # noqa: E402
from roughsea_torch.radiometry import LWIR, band_radiance, brightness_temperature  # noqa: E402
from roughsea_torch.renderer.hits import (footprint_fade, pixel_windows, sample_step, sweep_envelope,  # noqa: E402
                                          sweep_layout, visible_average, visible_samples)
from roughsea_torch.slopes import SlopeStatistics  # noqa: E402

H, W, HFOV, PITCH, T_SEA, SEED, TIME_S = 48, 64, 12.0, -6.0, 290.0, 11, 3.0
DIRECTIONS = {"upwind": (15.0, 0.0), "crosswind": (20.0, math.pi / 2)}
QUAD = Quadrature(outer=20, inner=20, hermite=12, width=7.5)  # the ray tracer's rule
K_TRACED = 64.0
DEFAULT = dict(step=0.25, min_step=1 / 32, across=1.0)  # TableSize's first-hit defaults until 2026-11-27 (now 1/64, 0.7)
INF = float("inf")
F64 = torch.float64


def to_slope_frame(vx, vy, cxy, wdir: float):
    c, s = math.cos(wdir), math.sin(wdir)
    return (vx * c * c + 2 * cxy * c * s + vy * s * s, vx * s * s - 2 * cxy * c * s + vy * c * c,
            (vy - vx) * c * s + cxy * (c * c - s * s))


class Case:
    """The scene, the model's inputs and the node-value table of one (direction, wind)."""

    def __init__(self, direction: str, wind: float, height: int = H, width: int = W):
        self.mast, self.wdir = DIRECTIONS[direction]
        self.wind = wind
        self.cams = rs.make_camera(height, width, hfov_deg=HFOV, altitude_m=self.mast, pitch_deg=PITCH)
        self.scene = rs.SeaScene(wind_speed=wind, wind_direction=self.wdir, sea_temperature=T_SEA, seed=SEED,
                                 time_s=TIME_S, foam=False, path=False)
        self.field = self.scene.wave_field(1, F64, torch.device("cpu"))
        self.ifov = float(1.0 / self.cams.fx[0])
        self.sky = load_sky("midlatitude_summer", LWIR, dtype=F64)
        self.m = band_refractive_index(LWIR, T_SEA).to(torch.complex128)
        self.rb = band_radiance(torch.tensor(T_SEA, dtype=F64), LWIR)
        cm = SlopeStatistics.cox_munk(wind, anisotropic=True)
        self.tot = (float(cm.var_upwind), float(cm.var_crosswind), float(cm.cov))
        self.table = None

    def node_footprint(self, cos_v: torch.Tensor) -> torch.Tensor:
        """F_s [m], the default sweep's sample footprint at a flat-sea view of zenith cosine cos_v."""
        rho = self.mast / cos_v
        return footprint(rho, cos_v, self.ifov * 2.0 * sample_step(cos_v, **DEFAULT))

    def build_table(self, vz_deg: tuple[float, float], los: tuple[float, float], n_vz=48, n_los=5, n_a=49, a_max=0.5):
        """T(θ̂, φ̂, a) [K] on a grid: the sweep's node value (see the module docstring)."""
        vz = torch.linspace(math.radians(vz_deg[0]), math.radians(vz_deg[1]), n_vz, dtype=F64)
        ph = torch.linspace(los[0], los[1], n_los, dtype=F64)
        a = torch.linspace(-a_max, a_max, n_a, dtype=F64)
        VZ, PH, A = torch.meshgrid(vz, ph, a, indexing="ij")
        cz = torch.cos(VZ)
        fs = self.node_footprint(cz)
        vaw = PH + self.wdir
        ex, ey = torch.cos(vaw), torch.sin(vaw)
        cx_, cy_, cxy_ = (v[0] for v in self.field.resolved_covariance(fs.reshape(1, -1)))
        cx_, cy_, cxy_ = (v.reshape(VZ.shape) for v in (cx_, cy_, cxy_))
        var_a = cx_ * ex * ex + 2 * cxy_ * ex * ey + cy_ * ey * ey
        kap = ((cy_ - cx_) * ex * ey + cxy_ * (ex * ex - ey * ey)) / var_a
        full = lambda v: torch.full_like(A, v)  # noqa: E731
        st = unresolved_statistics(full(self.tot[0]), full(self.tot[1]), full(self.tot[2]), PH, var_a, kap, A)
        L = apparent_radiance(VZ, PH, st, self.m, self.rb, self.sky, quadrature=QUAD)
        self.table = (brightness_temperature(L, LWIR), (vz[0], vz[-1]), (ph[0], ph[-1]), (a[0], a[-1]))

    def node_value(self, vz: torch.Tensor, los: torch.Tensor, a: torch.Tensor) -> torch.Tensor:
        """T at (θ̂ [rad], φ̂ [rad], a), trilinear in the table (border values beyond it)."""
        T, *lims = self.table
        los = self.los0 + torch.remainder(los - self.los0 + math.pi, 2 * math.pi) - math.pi
        norm = [2.0 * (v - lo) / (hi - lo) - 1.0 for v, (lo, hi) in zip((a, los, vz), lims[::-1])]
        grid = torch.stack(norm, -1).reshape(1, 1, 1, -1, 3)
        out = F.grid_sample(T[None, None], grid, mode="bilinear", padding_mode="border", align_corners=True)
        return out.reshape(a.shape)


def centre_rays(cams: PinholeCamera, rows: slice) -> tuple[torch.Tensor, torch.Tensor]:
    """Camera centre (3,) and the pixels' centre rays (h, W, 3), world frame (as ``raytrace.camera_rays``)."""
    Wd = int(cams.width[0])
    c64 = PinholeCamera(cams.intrinsics.double(), cams.extrinsics.double(), cams.height.double(), cams.width.double())
    centre = -(c64.rotation_matrix.transpose(-1, -2) @ c64.translation_vector)[0, :, 0]
    rr = torch.arange(rows.start, rows.stop, dtype=F64)
    v, u = torch.meshgrid(rr, torch.arange(Wd, dtype=F64), indexing="ij")
    uv = torch.stack([u, v], -1).reshape(1, -1, 2)
    pts = c64.unproject(uv, torch.ones(1, uv.shape[1], 1, dtype=F64))[0]
    d = torch.nn.functional.normalize(pts - centre, dim=-1)
    return centre, d.reshape(len(rr), Wd, 3)


def ray_side(case: Case, rows: slice, rays: int) -> dict:
    """Per pixel (h, W) means over its rays of: T_ray (a), T_node (b), a at F_s, its sign, the k ≤ 64
    slope along the view and its sign, the ground range of the hit; and each one's variance / rays."""
    tr = rt.trace_first_hits(case.cams, case.field, TIME_S, rays, K_TRACED, rows=rows)
    hit = tr["hit"][0]
    if not bool(hit.all()):
        raise RuntimeError("some rays did not hit within the trace")
    cz, vaw = tr["cos_view_zenith"][0], tr["view_azimuth_world"][0]
    x, y, sx, sy = (tr[k][0] for k in ("x", "y", "slope_x", "slope_y"))
    vz = torch.acos(cz.clamp(0.0, 1.0))
    los = vaw - case.wdir
    edges = case.field.bands.k_edges
    traced = case.field.band_covariance()[0][[o for o in range(len(edges) - 1) if edges[o + 1] <= K_TRACED]].sum(0)
    t_up, t_cr, t_cv = to_slope_frame(*(float(v) for v in traced), case.wdir)
    c, s = math.cos(case.wdir), math.sin(case.wdir)
    s_up, s_cr = sx * c + sy * s, -sx * s + sy * c
    tot = case.tot
    stats = SlopeStatistics.from_variances(torch.full_like(s_up, tot[0] - t_up), torch.full_like(s_up, tot[1] - t_cr),
                                           torch.full_like(s_up, tot[2] - t_cv)).shifted(s_up, s_cr)
    T_ray = brightness_temperature(apparent_radiance(vz, los, stats, case.m, case.rb, case.sky, quadrature=QUAD), LWIR)
    fs = case.node_footprint(cz)
    smp = case.field.sample(x.reshape(1, -1), y.reshape(1, -1), TIME_S, footprint=fs.reshape(1, -1))
    ex, ey = torch.cos(vaw), torch.sin(vaw)  # sea → sensor
    a = (smp["slope_x"][0].reshape(x.shape) * ex + smp["slope_y"][0].reshape(x.shape) * ey)
    a64 = sx * ex + sy * ey
    T_node = case.node_value(vz, los, a)
    centre, _ = centre_rays(case.cams, slice(0, 1))
    rng = torch.sqrt((x - centre[0]) ** 2 + (y - centre[1]) ** 2)
    q = dict(T=T_ray, Tn=T_node, a=a, face=(a > 0).to(F64), a64=a64, face64=(a64 > 0).to(F64), r=rng)
    out = {k: v.mean(-1) for k, v in q.items()}
    out.update({k + "_nv": v.var(-1) / v.shape[-1] for k, v in q.items()})
    out["cov_T_Tn"] = ((T_ray - T_ray.mean(-1, keepdim=True)) * (T_node - T_node.mean(-1, keepdim=True))).sum(-1) \
        / (rays - 1) / rays
    return out


def sweep_side(case: Case, rows: slice, n: int, elev: str, surface: rt.TracedSurface, interpolate: bool = False) -> dict:
    """Per pixel (h, W) the visible averages of T, a, its sign, the k ≤ 64 slope and its sign, and the
    ground range, for a sweep n× denser than the default whose visibility uses the elevation ``elev``
    ('Fs': at F_s; 'Fs/n': at the denser samples' own footprint; 'k64': the traced surface). With
    ``interpolate`` the slope a is read at the default sweep's samples and interpolated linearly in range
    to the denser ones (the values cost what the default's do; only the elevation is read n× denser)."""
    centre, d = centre_rays(case.cams, rows)
    rho = torch.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)
    tan_g, phi = (-d[..., 2] / rho).reshape(-1), torch.atan2(d[..., 1], d[..., 0]).reshape(-1)
    h = torch.tensor(case.mast, dtype=F64)
    t0 = time.perf_counter()
    sw = sweep_layout(case.field, 0, centre[:2], h, tan_g, phi, case.ifov, INF, tracks=1.0,
                      **{k: v / n for k, v in DEFAULT.items()})
    ns, nt = sw.shape
    X, Y = sw.x.reshape(1, -1), sw.y.reshape(1, -1)
    t_s = torch.tensor([TIME_S], dtype=F64)
    cos_k = torch.sin(torch.atan(sw.flat_depression()))  # flat Earth: the samples' view zenith cosines
    fs_node = case.node_footprint(cos_k)  # (ns,)
    if elev == "k64":
        eta = surface(X, Y)[0]
    else:
        fp = (fs_node if elev == "Fs" else sw.footprint)[:, None].expand(ns, nt).reshape(1, -1)
        eta = case.field.sample_unchecked(X, Y, t_s, fp, elevation=True, crest=False, slopes=False)["elevation"]
    t_dep, m = sweep_envelope(sw, eta[0].reshape(ns, nt))
    vis = visible_samples(m)  # (nt, ns)
    t_env = time.perf_counter() - t0
    jj, kk = vis.nonzero(as_tuple=True)
    Xv, Yv = sw.x[kk, jj][None], sw.y[kk, jj][None]
    ex, ey = -torch.cos(sw.az[jj]), -torch.sin(sw.az[jj])  # sea → sensor
    if interpolate and n > 1:  # a read at the default samples only, interpolated in range along each track
        coarse = sweep_layout(case.field, 0, centre[:2], h, tan_g, phi, case.ifov, INF, tracks=1.0, **DEFAULT)
        fs_c = case.node_footprint(torch.sin(torch.atan(coarse.flat_depression())))
        nc = coarse.shape[0]
        smp = case.field.sample_unchecked(coarse.x.reshape(1, -1), coarse.y.reshape(1, -1), t_s,
                                          fs_c[:, None].expand(nc, nt).reshape(1, -1), elevation=False, crest=False)
        ac = (smp["slope_x"][0].reshape(nc, nt) * -torch.cos(coarse.az) + smp["slope_y"][0].reshape(nc, nt)
              * -torch.sin(coarse.az))
        a_full = torch.stack([torch.from_numpy(np.interp(sw.r.numpy(), coarse.r.numpy(), ac[:, q].numpy()))
                              for q in range(nt)], 1)  # (ns, nt): the tracks' azimuths are the same in both
        a = a_full[kk, jj]
    else:
        smp = case.field.sample_unchecked(Xv, Yv, t_s, fs_node[kk][None], elevation=False, crest=False)
        a = smp["slope_x"][0] * ex + smp["slope_y"][0] * ey
    _, s64x, s64y = surface(Xv, Yv)
    a64 = s64x[0] * ex + s64y[0] * ey
    # the view zenith of the ray that meets the sample (its depression (h − η)/r), as the ray tracer's
    # rays carry theirs (the renderer takes the flat point's at r, but reads a departure from the mean there)
    vz = 0.5 * math.pi - torch.atan(t_dep[jj, kk].detach())
    los = torch.atan2(ey, ex) - case.wdir
    Tn = case.node_value(vz, los, a)
    chans = torch.stack([Tn, a, (a > 0).to(F64), a64, (a64 > 0).to(F64), sw.r[kk], torch.ones_like(a)])
    values = torch.zeros(chans.shape[0], nt, ns, dtype=F64)
    values[:, jj, kk] = chans
    j = ((phi - sw.p0) / sw.dphi).round().clamp(0, nt - 1).long()
    tau_t, tau_b = pixel_windows(tan_g, case.ifov)
    avg = visible_average(m, values, j, tau_t, tau_b).reshape(-1, *d.shape[:2])
    # the share of each window that the sweep covers (the renderer averages departures from the mean,
    # which count 0 where nothing is resolved; these are absolute quantities: averaged over the covered part)
    cover = avg[-1]
    names = ("Tn", "a", "face", "a64", "face64", "r")
    out = {k: v / cover for k, v in zip(names, avg[:-1])}
    out.update(ns=ns, nt=nt, n_vis=int(vis.sum()), t_env=t_env, cover=float(cover.min()))
    return out


def clutter(img: np.ndarray) -> np.ndarray:
    return img - img.mean(1, keepdims=True)


def blocks(img: np.ndarray, n: int) -> np.ndarray:
    h, w = img.shape
    return img[: h // n * n, : w // n * n].reshape(h // n, n, w // n, n).mean((1, 3))


def regress(x: np.ndarray, ref: np.ndarray, ref_nv: np.ndarray, n: int, cov_nv: np.ndarray | None = None) -> tuple:
    """(gain of x on ref, correlation, σ_x / σ_ref) of the clutter after n×n blocks, ref's sampling
    variance (ref_nv per pixel) removed; cov_nv the sampling covariance of x and ref where x has the
    same rays' noise (else x is noise-free)."""
    xb, rb = clutter(blocks(x, n)), clutter(blocks(ref, n))
    shrink = 1 - 1 / rb.shape[1]
    vr = (rb * rb).mean() - blocks(ref_nv, n).mean() / n**2 * shrink
    c = (xb * rb).mean() - (0.0 if cov_nv is None else blocks(cov_nv, n).mean() / n**2 * shrink)
    if vr <= 0:  # the reference's variance does not stand out of its sampling noise
        return math.nan, math.nan, math.nan
    return c / vr, c / math.sqrt(vr * (xb * xb).mean()), math.sqrt((xb * xb).mean() / vr)


def report(case: Case, rows: slice, ray: dict, sweeps: dict, textured: dict) -> None:
    npy = {k: v.numpy() for k, v in ray.items()}
    vz_rows = [90 - math.degrees(math.atan(float(-d[0, 32, 2] / math.hypot(d[0, 32, 0], d[0, 32, 1]))))
               for d in [centre_rays(case.cams, slice(r, r + 1))[1] for r in range(rows.start, rows.stop)]]
    bins = [(b, b + 8) for b in range(0, rows.stop - rows.start, 8)]
    print("\n### Where the seen surface lies (per-pixel means, averaged over the bin)\n")
    print("| bin (rows, view zenith) | image | ground range [m] | share a_Fs > 0 | mean a_Fs | "
          "share a_64 > 0 | mean a_64 | pixel r(a_Fs, rays') | gain of a_Fs on rays' (px / 4×4) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for b0, b1 in bins:
        lab = f"{rows.start + b0}–{rows.start + b1 - 1}, {vz_rows[b1 - 1]:.1f}–{vz_rows[b0]:.1f}°"
        sl = slice(b0, b1)
        print(f"| {lab} | rays (hits) | {npy['r'][sl].mean():.1f} | {npy['face'][sl].mean():.3f} | "
              f"{npy['a'][sl].mean():+.4f} | {npy['face64'][sl].mean():.3f} | {npy['a64'][sl].mean():+.4f} | 1 | 1 |")
        for name, s in sweeps.items():
            sv = {k: v.numpy() for k, v in s.items() if torch.is_tensor(v)}
            g1, r1, _ = regress(sv["a"][sl], npy["a"][sl], npy["a_nv"][sl], 1)
            g4, _, _ = regress(sv["a"][sl], npy["a"][sl], npy["a_nv"][sl], 4)
            print(f"| {lab} | sweep {name} | {sv['r'][sl].mean():.1f} | {sv['face'][sl].mean():.3f} | "
                  f"{sv['a'][sl].mean():+.4f} | {sv['face64'][sl].mean():.3f} | {sv['a64'][sl].mean():+.4f} | "
                  f"{r1:.2f} | {g1:.2f} / {g4:.2f} |")
    print("\n### Images: regression gain / correlation / σ ratio of each on (a) the ray tracer and (b) the node "
          "values on the rays' hits, pixel and 4×4 blocks\n")
    print("| bin | image | on (a): px gain | r | σ ratio | 4×4 gain | 4×4 r | on (b): px gain | 4×4 gain | 4×4 r | "
          "mean − (a) [K] |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    whole = [(0, rows.stop - rows.start)]
    imgs = {"(b) node values on hits": (npy["Tn"], npy["cov_T_Tn"])}
    imgs.update({f"renderer {k}": (v, None) for k, v in textured.items()})
    imgs.update({f"sweep {k}": (v["Tn"].numpy(), None) for k, v in sweeps.items()})
    for b0, b1 in bins + whole:
        lab = f"{rows.start + b0}–{rows.start + b1 - 1}, {vz_rows[b1 - 1]:.1f}–{vz_rows[b0]:.1f}°"
        sl = slice(b0, b1)
        for name, (img, cnv) in imgs.items():
            ga1, ra1, sa1 = regress(img[sl], npy["T"][sl], npy["T_nv"][sl], 1, None if cnv is None else cnv[sl])
            ga4, ra4, _ = regress(img[sl], npy["T"][sl], npy["T_nv"][sl], 4, None if cnv is None else cnv[sl])
            if name.startswith("(b)"):
                gb1 = gb4 = rb4 = 1.0
            else:
                gb1, _, _ = regress(img[sl], npy["Tn"][sl], npy["Tn_nv"][sl], 1)
                gb4, rb4, _ = regress(img[sl], npy["Tn"][sl], npy["Tn_nv"][sl], 4)
            print(f"| {lab} | {name} | {ga1:.2f} | {ra1:.2f} | {sa1:.2f} | {ga4:.2f} | {ra4:.2f} | {gb1:.2f} | "
                  f"{gb4:.2f} | {rb4:.2f} | {float((img[sl] - npy['T'][sl]).mean()):+.3f} |")
    if textured and sweeps:
        ref_name = next(iter(sweeps))
        ref = sweeps[ref_name]["Tn"].numpy()
        print(f"\n### The renderer's images on the sweep {ref_name} with exact node values (same geometry)\n")
        print("| bin | renderer setting | px gain | px r | 4×4 gain | 4×4 r |")
        print("|---|---|---:|---:|---:|---:|")
        zero = np.zeros_like(ref)
        for b0, b1 in bins + whole:
            lab = f"{rows.start + b0}–{rows.start + b1 - 1}, {vz_rows[b1 - 1]:.1f}–{vz_rows[b0]:.1f}°"
            sl = slice(b0, b1)
            for name, img in textured.items():
                g1, r1, _ = regress(img[sl], ref[sl], zero[sl], 1)
                g4, r4, _ = regress(img[sl], ref[sl], zero[sl], 4)
                print(f"| {lab} | {name} | {g1:.2f} | {r1:.2f} | {g4:.2f} | {r4:.2f} |")


RENDER_SETTINGS = {  # TableSize fields (with texture_hit="first") of the renderer's images compared
    "x9": dict(texture_first=9),  # the first hit's node count before it became 17
    "default": {},
    "x33": dict(texture_first=33),
    "quad": dict(texture_quadrature=(20, 20), texture_quadrature_width=7.5),
    "z65": dict(texture_zenith=65),
    "x33+quad+z65": dict(texture_first=33, texture_quadrature=(20, 20), texture_quadrature_width=7.5, texture_zenith=65),
    "across0.5+min1/128": dict(texture_hit_across=0.5, texture_hit_min_step=1 / 128),
}


def renderer_image(case: Case, rows: slice, fields: dict) -> np.ndarray:
    """The renderer's textured image (brightness temperature, flat Earth, as the pipeline renders it)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        img = rs.render(case.cams, case.scene, output="brightness_temperature", earth_radius_m=INF,
                        table=rs.TableSize(texture_hit="first", **fields))
    return img[0, 0, rows].double().numpy()


def cost(direction: str, wind: float, variants: list[str], repeats: int = 3) -> None:
    """Elevation reads, visible samples and time of the sweep's layout + elevation + envelope of each
    variant on a 256×320 camera (the rest of the render is the same for all: the values are read at the
    visible samples only, counted here)."""
    case = Case(direction, wind, 256, 320)
    surf = rt.TracedSurface(case.field, TIME_S, K_TRACED)
    centre, d = centre_rays(case.cams, slice(0, 256))
    sea = d[..., 2] < 0
    rho = torch.sqrt(d[..., 0] ** 2 + d[..., 1] ** 2)
    tan_g, phi = (-d[..., 2] / rho)[sea], torch.atan2(d[..., 1], d[..., 0])[sea]
    h = torch.tensor(case.mast, dtype=F64)
    t_s = torch.tensor([TIME_S], dtype=F64)
    print("\n### Cost on a 256×320 camera (float64, one thread): layout + elevation reads + envelope\n")
    print("| variant | samples (ns × nt) | elevation reads / sea pixel | visible samples / sea pixel | time [s] |")
    print("|---|---:|---:|---:|---:|")
    for v in variants:
        n, elev = int(v.split(":")[0][1:]), v.split(":")[1]
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            sw = sweep_layout(case.field, 0, centre[:2], h, tan_g, phi, case.ifov, INF, tracks=1.0,
                              **{k: val / n for k, val in DEFAULT.items()})
            ns, nt = sw.shape
            cos_k = torch.sin(torch.atan(sw.flat_depression()))
            eta_rows = []
            for k0 in range(0, ns, max(1, 4_000_000 // nt)):  # in chunks of samples
                k1 = min(ns, k0 + max(1, 4_000_000 // nt))
                X, Y = sw.x[k0:k1].reshape(1, -1), sw.y[k0:k1].reshape(1, -1)
                if elev == "k64":
                    eta_rows.append(surf(X, Y)[0].reshape(k1 - k0, nt))
                else:
                    fp = (case.node_footprint(cos_k[k0:k1]) if elev == "Fs" else sw.footprint[k0:k1])
                    fp = fp[:, None].expand(k1 - k0, nt).reshape(1, -1)
                    eta_rows.append(case.field.sample_unchecked(X, Y, t_s, fp, elevation=True, crest=False,
                                                                slopes=False)["elevation"][0].reshape(k1 - k0, nt))
            _, m = sweep_envelope(sw, torch.cat(eta_rows))
            nvis = int(visible_samples(m).sum())
            times.append(time.perf_counter() - t0)
        P = int(sea.sum())
        print(f"| {v} | {ns} × {nt} | {ns * nt / P:.0f} | {nvis / P:.1f} | {sorted(times)[len(times) // 2]:.2f} |",
              flush=True)


def time_render(direction: str, wind: float, settings: list[str], repeats: int = 3) -> None:
    """Median time of one 256×320 first-hit render (float32, the renderer's defaults otherwise) per
    ``RENDER_SETTINGS`` entry, each timed in turn in one loop after a warm-up."""
    case = Case(direction, wind, 256, 320)
    times = {k: [] for k in settings}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for rep in range(repeats + 1):
            for k in settings:
                t0 = time.perf_counter()
                rs.render(case.cams, case.scene, output="brightness_temperature",
                          table=rs.TableSize(texture_hit="first", **RENDER_SETTINGS[k]))
                if rep:
                    times[k].append(time.perf_counter() - t0)
    print("\n### One 256×320 first-hit render (float32, one thread), median of", repeats, "\n")
    print("| TableSize setting | time [s] | × default |")
    print("|---|---:|---:|")
    base = sorted(times[settings[0]])[repeats // 2]
    for k in settings:
        t = sorted(times[k])[repeats // 2]
        print(f"| {k} | {t:.2f} | {t / base:.2f} |", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wind", type=float, default=5.0)
    ap.add_argument("--direction", default="upwind", choices=list(DIRECTIONS))
    ap.add_argument("--rows", type=int, nargs=2, default=(8, 40))
    ap.add_argument("--rays", type=int, default=32)
    ap.add_argument("--variants", nargs="+", default=["n1:Fs", "n2:Fs/2", "n4:Fs/4", "n4:Fs", "n8:Fs/8", "n8:k64"])
    ap.add_argument("--render", nargs="*", default=[], choices=list(RENDER_SETTINGS),
                    help="also the renderer's own first-hit images with these TableSize settings")
    ap.add_argument("--cost", action="store_true", help="only the cost table, on a 256×320 camera")
    ap.add_argument("--time-render", nargs="+", choices=list(RENDER_SETTINGS), default=None,
                    help="only the time of 256×320 renders with these settings (the first is the reference)")
    args = ap.parse_args()
    torch.set_num_threads(1)
    if args.cost:
        cost(args.direction, args.wind, args.variants)
        return
    if args.time_render:
        time_render(args.direction, args.wind, args.time_render)
        return
    rows = slice(*args.rows)
    case = Case(args.direction, args.wind)
    t0 = time.perf_counter()
    _, dc = centre_rays(case.cams, slice(H // 2, H // 2 + 1))
    case.los0 = math.atan2(-float(dc[0, W // 2, 1]), -float(dc[0, W // 2, 0])) - case.wdir  # centre ray's φ̂
    case.build_table((78.0, 89.5), (case.los0 - 0.15, case.los0 + 0.15))
    print(f"node table {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    t0 = time.perf_counter()
    ray = ray_side(case, rows, args.rays)
    print(f"rays {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    surf = rt.TracedSurface(case.field, TIME_S, K_TRACED)
    sweeps = {}
    for v in args.variants:
        t0 = time.perf_counter()
        parts = v.split(":")
        sweeps[v] = sweep_side(case, rows, int(parts[0][1:]), parts[1], surf, interpolate=parts[-1] == "i")
        s = sweeps[v]
        print(f"sweep {v}: {s['ns']}×{s['nt']} samples, {s['n_vis']} visible, window covered ≥ {s['cover']:.4f}, "
              f"{time.perf_counter() - t0:.1f} s", file=sys.stderr)
    _, d = centre_rays(case.cams, rows)
    cz = -d[..., 2]
    Lpix = footprint(case.mast / cz, cz, torch.tensor(case.ifov, dtype=F64))
    g = footprint_fade(case.field, 0, Lpix)
    print(f"footprint fade g over the rows: {float(g.min()):.3f}–{float(g.max()):.3f}", file=sys.stderr)
    textured = {k: renderer_image(case, rows, RENDER_SETTINGS[k]) for k in args.render}
    print(f"## {args.direction} {args.wind:g} m/s, rows {rows.start}–{rows.stop - 1}, {args.rays} rays per pixel")
    report(case, rows, ray, sweeps, textured)


if __name__ == "__main__":
    main()
