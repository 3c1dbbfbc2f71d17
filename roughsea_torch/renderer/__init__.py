"""The renderer: kornia cameras + a :class:`SeaScene` → infrared images of the sea (B, 1, H, W).

The user API is what this package exports: :func:`render`, :class:`SeaRenderer`, :class:`SeaScene`,
:class:`TableSize`, :func:`release_workspace`. Its modules, in the order a render runs through them
(``docs/architecture.md`` follows one pixel through them):

- :mod:`.scene` — :class:`SeaScene` and its per-image values (:class:`~.scene.SceneParameters`);
- :mod:`.settings` — :class:`TableSize` and the chunking;
- :mod:`.plan` — what a render needs: which terms are on, the tables' layout and nodes;
- :mod:`.coordinates` — the spans of view angles an image covers, and a pixel's table coordinates;
- :mod:`.spectral` — Chebyshev–Lobatto nodes and their resampling to fine tables;
- the terms: :mod:`.sky_terms` (the sky, the sun's disk, the day sky), :mod:`.path` (the air),
  :mod:`.foam_terms` (whitecaps), :mod:`.glint` (sun glint), :mod:`.texture` (textured seas) and
  :mod:`.hits` (what a pixel sees of the resolved waves near grazing);
- the methods: :mod:`.table` (the default: nodes → fine tables → one lookup per pixel → per-pixel
  terms; :mod:`.pixels` its in-place fast path) and :mod:`.direct` (every pixel evaluated);
- :mod:`.api` — :func:`render` and :class:`SeaRenderer`; :mod:`.output` — kelvin.

Names without a leading underscore in these modules are the package's internal API, shared between
its modules (documented where they are defined); only the names above are promised to users.
"""

from .api import SeaRenderer, render
from .pixels import release_workspace
from .scene import SceneParameters, SeaScene, check_foam
from .settings import DEFAULT_CHUNK, TableSize, images_per_chunk

__all__ = ["render", "SeaRenderer", "SeaScene", "TableSize", "release_workspace", "SceneParameters", "check_foam",
           "images_per_chunk", "DEFAULT_CHUNK"]
