"""The table method's settings: :class:`TableSize` (node counts of the per-image tables and of their
fine resampling) and the chunking of a render (how many images' per-pixel temporaries are held at
once). How the defaults were chosen, with the accuracy each setting buys against per-pixel
evaluation: ``docs/notes/table_size.md``.
"""

from __future__ import annotations

from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

import numpy as np

__all__ = ["TableSize", "DEFAULT_CHUNK", "FINE_OVERHANG", "images_per_chunk"]

DEFAULT_CHUNK = 4  # images per chunk of an expectation render (render's ``chunk``; textured scenes: 1)
FINE_OVERHANG = 2  # fine cells beyond each end of a node interval, so no pixel reads a table's clamped border


def images_per_chunk(scene: Any, chunk: Any = None) -> Any:
    """Images per chunk of pixels: ``chunk`` if given (render checks it), else 1 for a textured scene
    (its per-pixel work holds a dozen more full-size temporaries) and ``DEFAULT_CHUNK`` otherwise."""
    return chunk if chunk is not None else 1 if scene.seed is not None else DEFAULT_CHUNK


@dataclass(frozen=True)
class TableSize:
    """Node counts of the table method: Chebyshev–Lobatto nodes at which the model is evaluated per
    image, and the fine grids they are resampled to (read per pixel by bilinear ``grid_sample``).
    The defaults keep the table within a few 1e-6 of per-pixel evaluation (``method="direct"``);
    ``docs/notes/table_size.md`` has the measurements behind each.

    The mean (expectation) table, over ζ = asinh(cos θ̂/ε) (θ̂ the view zenith, ε ~ a quarter of the
    smallest rms slope) and the azimuth coordinate of the view from the upwind axis:

    Args:
        zenith: nodes in ζ.
        azimuth: nodes in relative azimuth (anisotropic slopes only).
        azimuth_thin, zenith_thin, fine_azimuth_thin: nodes in azimuth and in ζ, and fine columns,
            when some image's slope ellipse is thin (minor/major rms slope < 0.2: Cox–Munk below
            ~0.04 m/s, or |r| near 1), where R_a changes sharply with azimuth at grazing views.
        zenith_narrow: nodes in ζ when some image's ellipse is narrow but not thin (ratio < 0.5).
        azimuth_day: nodes in relative azimuth when the sea reflects a scattered daytime sky
            (``SeaScene(aerosol=)``, tabulated piecewise linearly in azimuth). A render with every
            azimuth in view (looking down at the nadir) or ``span="full"`` takes 2·azimuth_day − 1
            nodes and twice ``fine_azimuth`` columns, and its texture 4·(texture_azimuth_sun − 1) + 1
            nodes and four times ``fine_texture_azimuth`` columns, for the whole render.
        glint, glint_tolerance: Chebyshev–Lobatto nodes per axis (ζ, azimuth) of the glint's smooth
            factor L_sun G1 / D (sunny scenes without texture whose table runs over the unfolded
            azimuth); each pixel applies the sharp factor P ρ t itself. An image whose table misses
            ``glint_tolerance`` (relative to the radiance, at the fine cells' centres, checked
            against direct evaluation) keeps the whole glint per pixel.
        fine_zenith, fine_azimuth: rows and columns of the fine table.
        fine_sky: rows of the sky block of the fine table, uniform in the cosine of the ray's zenith
            over the span of the image's sky pixels.
        span: ``"pixels"`` (default): nodes only over the angles the image's sea pixels span;
            ``"full"``: over every angle (θ̂ in [0°, 90°], every azimuth), for comparison.

    The texture volume of textured scenes (``SeaScene(seed=)``, :mod:`roughsea_torch.renderer.texture`):

    Args:
        texture: nodes in x = a/σ_a, the flat-point quantile of the resolved along-view slope,
            Chebyshev–Lobatto over ±``texture_width``; beyond it the border value.
        texture_first: the same with ``texture_hit="first"``, where x is the resolved slope at the hit
            as it is: the model's response is strongly curved in it near grazing, and 9 nodes (0 and
            ±1.72 where the slopes are) lose 6–23 % of the clutter's contrast against the ray tracer
            at 5 m/s, 81–88° (``docs/texture_first_geometry.md``); 17 nodes cost 1.0–1.25×. Since the
            sweep's finer samples (2026-11-27) more of them reach the edges of x, where 17 nodes
            leave 1.1 % of the clutter's σ (rms) against 65: 25 (0.25 %), within the timing noise.
        texture_zenith, texture_zenith_sun: ζ nodes of the texture (of a sunny scene, whose volume
            also carries the visible quantile x' = a'/σ_a of each pixel's unresolved Gaussian).
        texture_azimuth_sun: azimuth nodes of the texture of a sunny scene (on the mean table's span).
        fine_texture, fine_texture_zenith, fine_texture_azimuth: the fine texture volume (x, ζ,
            azimuth), read trilinearly per sea pixel.
        texture_quadrature: (outer, inner) Gauss–Legendre nodes of the model at the texture nodes
            (the departure from the mean is the difference of two evaluations on this rule).
        texture_quadrature_steep, texture_steep_zenith_deg: the rule of the texture nodes whose view
            zenith is below ``texture_steep_zenith_deg`` [deg].
        texture_quadrature_width: half-width [standard deviations] of the Gaussian window of the
            texture nodes' rule (the render's quadrature's, if narrower).
        texture_min_band_share: per image, the octaves of the wave field that carry less than this
            share of its slope variance (and of its crest variable's) are left out of the
            realization, their variance left to the unresolved statistics; 0 keeps every band.
        texture_hit: where a pixel meets the resolved waves. ``"first"``: where its ray
            first meets the resolved surface (:mod:`~roughsea_torch.renderer.hits`: a crest hides the
            trough behind it, facets turned away are never seen), the resolved slope there as it is.
            ``"flat"`` (default): at its flat-sea point, the resolved slope's quantile mapped onto the
            visible-slope distribution (:func:`~roughsea_torch.clutter.visible_slope`; its ensemble
            mean is the expectation image exactly, but near grazing it has neither parallax nor
            hiding). The table method's setting; ``method="direct"`` evaluates the flat point per pixel.
        texture_hit_step, texture_hit_min_step, texture_hit_across, texture_hit_finest, texture_hit_tracks:
            the sweep of ``texture_hit="first"``: its samples' spacing in depression [pixels],
            ``across`` · cos θ̂/2 clamped into [``min_step``, ``step``] and at most ``finest`` · cos θ̂ /
            (2 R δ) (each sample filtered at twice its spacing's footprint along the view: near grazing
            the waves down to ``across`` times the pixel's width across the view, and down to ``finest``
            metres where that width has grown beyond it; 0: no such cap;
            :func:`~roughsea_torch.renderer.hits.sample_step`), and its ground tracks per pixel width
            (with n = ⌊tracks⌋ ≥ 2 a pixel averages the n tracks across its width, δ/n apart, a box
            across the view as a camera's pixel is, and the glint takes the mean of its centre ray's
            first hits on them; 1: the track through its centre). Defaults 1/4, 1/512, 0.7,
            0.15 m, 2: against a ray trace of the same waves at 80–88.5° (two realizations, 5–15 m/s,
            upwind and crosswind, ``SeaScene(shadowing="multiscale")``) σ within 0.85–1.2 in 30 and 30
            of 30 bins, the ensemble mean within 0.05 K in 30 and 30, where the former defaults (1/64,
            no cap, one track) gave 28 and 26, 28 and 27, at about 3× their time (``docs/texture.md`` §11).
        texture_hit_visibility: in (0, 1]: the factor on the sweep's sample footprint F_s of the
            elevation its running horizon (the visibility) is taken on; its spacings (step, min_step,
            across) are scaled by it, while the slopes, crest, texture and foam stay filtered at F_s
            (``docs/texture_first_geometry.md``). 1 (default): one layout; 0.5: the elevation at
            F_s/2 on twice the samples.
        texture_hit_cross: with ``texture_hit="first"``, the texture of the resolved slope *across* the
            line of sight as well (default True): a tilt across the view turns the reflected ray
            sideways and changes the radiance to second order, which crosswind near 80° carries a
            third of the clutter's block variance (``docs/texture.md`` §5). The node values take it as
            a quadratic in y = c_r/σ_r (the across-view residual of the resolved slope over its rms)
            through y = ±√3 whose mean over y ~ N(0, 1) is the along-view node value (three-point
            Gauss–Hermite), so the ensemble mean stays the along-view texture's; two more evaluations
            per node. False: statistical, as with ``"flat"``.
        texture_hit_lean, texture_hit_lean_across: with ``texture_hit="first"``, the unresolved waves'
            own slopes at each sweep sample (default False): their mean and covariance over the sample's
            patch (``texture_hit_lean_across`` · R δ across the view × the sample's length along it, taken
            isotropic with that area; :mod:`~roughsea_torch.renderer.lean`), the mean (as much of it as the
            unresolved Gaussian holds) added to the resolved slope where the texture is read, the
            covariance's along-view variance scaling the unresolved Gaussian's (two more evaluations per
            node: a quadratic in the log of that scale through ×½ and ×2), each sample weighted by its
            patch's visible projected area. Pair it with ``SeaScene(shadowing="multiscale")``; 1.6–1.8×
            the first hit's time. Near grazing at light wind a pixel holds few patches of the waves
            shorter than the samples' footprint, and their realization carries clutter an expectation
            over them does not (``docs/subpixel_clutter.md``).
        texture_hit_foam_tilt: with ``texture_hit="first"`` and whitecaps on the crests, each visible sample's
            foam seen at its own resolved facet's incidence (default True), not at the mean plane's view
            zenith θ̂: near grazing the crests that carry the foam lean towards the camera, and foam's
            emissivity and reflected sky change steeply with incidence (LWIR, 15 m/s: a foam patch 6.6 K
            darker than the water at 88°, 0.9 K at 80°; ``docs/foam_table.md``). Added per sample as
            f (R_foam(θ_f) − R_foam(θ̂)) for each state, θ_f from cos θ_f = (cos θ̂ + sin θ̂ a)/√(1 + |s|²) (s the
            reconciled resolved slope, a its component towards the sensor), through the path's τ.
            False: the foam in the mean plane, as with ``"flat"``.
        texture_antialias: True (default): the flat-point texture and crest-foam fraction are
            low-pass filtered along the image's columns, with a zero at the rows' Nyquist frequency
            (:mod:`~roughsea_torch.renderer.antialias`: the resolved band there would fold into
            one-pixel horizontal lines; the ensemble mean is unchanged); False: unfiltered. Both
            methods; the sweep is not filtered.

    The whitecaps of textured seas (:mod:`roughsea_torch.whitecaps`):

        foam_trails: ``False`` (default): the residual foam sits where the crests break now (the
            whitecap cover of one instant, E[f] = W); ``True``: it is the breaking of the last seconds,
            drifting and fading (trails; 13 more reads of the wave field per pixel, 2–5× a textured
            storm's time). Both methods.

    The glint of textured seas (:mod:`roughsea_torch.glitter`, ``docs/glitter.md``):

    Args:
        glitter: ``False`` (default): each textured pixel's glint is the expectation over its
            unresolved facets (a smooth "moon path"). ``True``: that glint times a random factor of
            mean 1 whose variance F (1 + κ)/N follows the expected number N of glitter spots in the
            pixel's footprint, coherent in time (the sea's seed and time set it). Textured sunny scenes
            of the table method only (``method="direct"`` and scenes without ``seed`` ignore it).
        glitter_lifetime_s: the glitter's time step τ [s] in (0, 100] (default 0.25 s): a pixel's
            factor decorrelates over about τ, its hotspots last 0.68 τ (0.17 s: Schwering's measured
            0.15–0.2 s).

    For accuracy finer than the defaults, e.g. MWIR day skies about the sun:
    ``TableSize(texture_quadrature=(20, 16), texture_azimuth_sun=17, fine_texture_azimuth=64)``.
    """

    zenith: int = 17
    azimuth: int = 7
    fine_zenith: int = 3072
    fine_azimuth: int = 64
    span: str = "pixels"
    azimuth_thin: int = 33
    fine_sky: int = 2048
    zenith_thin: int = 41
    fine_azimuth_thin: int = 128
    texture: int = 9
    texture_first: int = 25
    texture_zenith: int = 33
    texture_zenith_sun: int = 65
    texture_width: float = 4.5
    fine_texture: int = 129
    fine_texture_zenith: int = 512
    fine_texture_azimuth: int = 16
    texture_quadrature: tuple = (12, 16)
    texture_quadrature_steep: tuple = (16, 16)
    texture_steep_zenith_deg: float = 40.0
    texture_quadrature_width: float = 4.5
    texture_min_band_share: float = 1e-8
    texture_hit: str = "flat"
    texture_antialias: bool = True
    texture_hit_step: float = 0.25
    texture_hit_min_step: float = 0.001953125
    texture_hit_across: float = 0.7
    texture_hit_tracks: float = 2.0
    texture_hit_finest: float = 0.15
    texture_hit_visibility: float = 1.0
    texture_hit_cross: bool = True
    texture_hit_lean: bool = False
    texture_hit_lean_across: float = 0.7
    texture_hit_foam_tilt: bool = True
    texture_azimuth_sun: int = 9
    zenith_narrow: int = 21
    azimuth_day: int = 25
    glint: int = 33
    glint_tolerance: float = 1e-5
    glitter: bool = False
    glitter_lifetime_s: float = 0.25
    foam_trails: bool = False

    def __post_init__(self) -> None:
        if self.span not in ("pixels", "full"):
            raise ValueError(f"TableSize.span must be 'pixels' or 'full'; got {self.span!r}")
        if self.texture_hit not in ("first", "flat"):
            raise ValueError(f"TableSize.texture_hit must be 'first' or 'flat'; got {self.texture_hit!r}")
        if not isinstance(self.texture_antialias, (bool, np.bool_)):
            raise ValueError(f"TableSize.texture_antialias must be True or False; got {self.texture_antialias!r}")
        for name in ("zenith", "azimuth", "azimuth_thin", "zenith_thin", "zenith_narrow", "azimuth_day", "texture", "texture_first",
                     "texture_zenith", "texture_zenith_sun", "texture_azimuth_sun", "glint"):
            if int(getattr(self, name)) < 2:
                raise ValueError(f"TableSize.{name} must be >= 2")
        for name in ("fine_zenith", "fine_azimuth", "fine_sky", "fine_azimuth_thin", "fine_texture",
                     "fine_texture_zenith", "fine_texture_azimuth"):
            if int(getattr(self, name)) < 4 * FINE_OVERHANG + 2:
                raise ValueError(f"TableSize.{name} must be >= {4 * FINE_OVERHANG + 2}")
        for name in ("texture_quadrature", "texture_quadrature_steep"):
            rule = getattr(self, name)
            if (not isinstance(rule, (tuple, list)) or len(rule) != 2
                    or not all(isinstance(v, Integral) and not isinstance(v, (bool, np.bool_)) and 1 <= v <= 512
                               for v in rule)):
                raise ValueError(f"TableSize.{name} must be (outer, inner), two ints in [1, 512]; got {rule!r}")
            object.__setattr__(self, name, tuple(int(v) for v in rule))  # hashable (tables are cached by it)
        for name, lo, hi in (("texture_steep_zenith_deg", 0.0, 90.0), ("texture_quadrature_width", 1.0, 40.0),
                             ("texture_hit_step", 0.01, 1.0), ("texture_hit_min_step", 0.001, 1.0),
                             ("texture_hit_across", 0.1, 100.0), ("texture_hit_tracks", 0.25, 16.0),
                             ("texture_hit_visibility", 0.125, 1.0), ("texture_hit_lean_across", 0.05, 4.0),
                             ("texture_hit_finest", 0.0, 100.0)):
            v = getattr(self, name)
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, Real) or not lo <= float(v) <= hi:
                raise ValueError(f"TableSize.{name} must be a number in [{lo:g}, {hi:g}]; got {v!r}")
            object.__setattr__(self, name, float(v))
        for name in ("texture_hit_cross", "texture_hit_lean", "texture_hit_foam_tilt"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise ValueError(f"TableSize.{name} must be a bool; got {getattr(self, name)!r}")
        if self.texture_hit_lean and self.texture_hit != "first":
            raise ValueError("TableSize.texture_hit_lean=True needs texture_hit='first' (the patch moments are read at the "
                             f"first-hit sweep's samples); got texture_hit={self.texture_hit!r}")
        if not isinstance(self.foam_trails, (bool, np.bool_)):
            raise ValueError(f"TableSize.foam_trails must be a bool; got {self.foam_trails!r}")
        if not isinstance(self.glitter, (bool, np.bool_)):
            raise ValueError(f"TableSize.glitter must be a bool; got {self.glitter!r}")
        tau = self.glitter_lifetime_s
        if isinstance(tau, (bool, np.bool_)) or not isinstance(tau, Real) or not 0.0 < float(tau) <= 100.0:
            raise ValueError(f"TableSize.glitter_lifetime_s must be a number in (0, 100] s; got {tau!r}")
        object.__setattr__(self, "glitter_lifetime_s", float(tau))
        share = self.texture_min_band_share
        if isinstance(share, bool) or not isinstance(share, (int, float)) or not 0.0 <= float(share) < 1.0:
            raise ValueError(f"TableSize.texture_min_band_share must be a number in [0, 1); got {share!r}")
