"""A few training steps of a tiny target-segmentation net on ships pasted onto sea rendered on the fly.

Each step: draw ship silhouettes (hull + superstructure, each with its own temperature) as
(temperature, alpha) chips; ``RandomSeaBackground(mode="composite")`` renders a random sea under
them (wind, temperatures, atmosphere, pose), blends the ships in radiance and runs a LWIR sensor
model (blur, NETD noise, fixed pattern, 14-bit counts); the net learns the ship masks. The loop
times the augmentation and the net's step separately and prints the share of a step that sea
generation costs. It writes a picture grid of one batch as a person would look at it (percentile
stretch, 8 bit) with the masks outlined, and the loss curve.

    python examples/train_segmentation.py --steps 60 --out outputs/train

CPU-friendly: 128×160 images, batch 8, ~1 min on 2 cores.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import torch
import torch.nn.functional as F
from torch import nn

from roughsea_torch.augmentation import RandomSeaBackground
from roughsea_torch.sensor import SensorModel, ToDisplay


def ship_chips(batch: int, height: int, width: int, generator: torch.Generator, sea_temperature: float = 292.0,
               supersample: int = 4) -> torch.Tensor:
    """(B, 2, H, W): a ship's temperature [K] (channel 0) and its anti-aliased opacity (channel 1).

    One or two ships per image, in the lower 70 % of the frame (below a horizon near the top for
    the default pitch range), hull 12–40 px long, warmer than the sea by 1–8 K, the superstructure
    by 4–20 K."""
    s = supersample
    Hs, Ws = height * s, width * s
    yy = torch.arange(Hs, dtype=torch.float32)[:, None] + 0.5
    xx = torch.arange(Ws, dtype=torch.float32)[None, :] + 0.5
    temp = torch.full((batch, Hs, Ws), sea_temperature)
    alpha = torch.zeros(batch, Hs, Ws)

    def u(lo: float, hi: float) -> float:
        return lo + (hi - lo) * float(torch.rand((), generator=generator))

    for b in range(batch):
        for _ in range(1 + int(torch.rand((), generator=generator) < 0.5)):
            L = u(12, 40) * s
            h = L * u(0.12, 0.22)
            x0, y0 = u(0.05, 0.95) * Ws - L / 2, u(0.35, 0.95) * Hs
            hull = (xx > x0) & (xx < x0 + L) & (yy > y0 - h) & (yy < y0) & ((yy - (y0 - h)) < h * (1.3 - 0.6 * ((xx - x0) / L - 0.5).abs()))
            sx0, sw, sh = x0 + L * u(0.25, 0.55), L * u(0.15, 0.3), h * u(0.8, 1.6)
            sup = (xx > sx0) & (xx < sx0 + sw) & (yy > y0 - h - sh) & (yy <= y0 - h)
            temp[b] = torch.where(hull, sea_temperature + u(1, 8), temp[b])
            temp[b] = torch.where(sup, sea_temperature + u(4, 20), temp[b])
            alpha[b] = torch.where(hull | sup, 1.0, alpha[b])
    # average in radiance-like weights is overkill for a mask edge: box-filter both channels
    a = F.avg_pool2d(alpha[:, None], s)
    t = F.avg_pool2d((temp * alpha)[:, None], s) / a.clamp_min(1e-6)
    t = torch.where(a > 0, t, torch.full_like(t, sea_temperature))
    return torch.cat([t, a], 1)


class TinySegNet(nn.Module):
    """Four 3×3 conv layers (one stride-2 stage) and a 1×1 head: ~20k parameters."""

    def __init__(self, width: int = 24):
        super().__init__()
        self.body = nn.Sequential(
            nn.Conv2d(1, width, 3, padding=1), nn.ReLU(),
            nn.Conv2d(width, width, 3, padding=1, stride=2), nn.ReLU(),
            nn.Conv2d(width, width, 3, padding=2, dilation=2), nn.ReLU(),
            nn.Conv2d(width, width, 3, padding=1), nn.ReLU(),
        )
        self.head = nn.Conv2d(width, 1, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return F.interpolate(self.head(self.body(x)), size=x.shape[-2:], mode="bilinear", align_corners=False)


def normalise(counts: torch.Tensor) -> torch.Tensor:
    """Per-image standardisation of sensor counts (what a detector's input layer would see)."""
    m = counts.mean((1, 2, 3), keepdim=True)
    s = counts.std((1, 2, 3), keepdim=True).clamp_min(1.0)
    return (counts - m) / s


def make_augmentation(seed: int = 0, texture: bool = True) -> RandomSeaBackground:
    return RandomSeaBackground(
        texture=texture,
        # the air a few kelvin from the sea, mostly colder, as over the open sea: T_air = T_sea + [-3, 1] K
        wind_speed=(1.0, 14.0), sea_temperature=(286.0, 298.0), air_sea_difference=(-3.0, 1.0),
        atmospheres=["midlatitude_summer", "tropical", "us_standard"], altitude_m=(8.0, 40.0),
        pitch_deg=(-6.0, -2.0), roll_deg=(-1.5, 1.5), hfov_deg=(12.0, 24.0),
        mode="composite", sensor=SensorModel.typical_lwir(seed=seed),
    )


def iou(logits: torch.Tensor, mask: torch.Tensor) -> float:
    pred = logits > 0
    inter = (pred & mask).sum().item()
    union = (pred | mask).sum().item()
    return inter / max(union, 1)


def train(steps: int, batch: int, height: int, width: int, seed: int, log=print) -> dict:
    torch.manual_seed(seed)
    g = torch.Generator().manual_seed(seed)
    aug = make_augmentation(seed)
    net = TinySegNet()
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    t_aug, t_net, losses, ious = [], [], [], []
    batch0 = None
    for step in range(steps):
        t0 = time.perf_counter()
        chips = ship_chips(batch, height, width, g)
        x = aug(chips, generator=g)  # (B, 2, H, W): channel 0 counts, channel 1 alpha
        mask = chips[:, 1:2] > 0.5
        inp = normalise(x[:, :1])
        t1 = time.perf_counter()
        logits = net(inp)
        pos = mask.float().mean().clamp_min(1e-3)
        loss = F.binary_cross_entropy_with_logits(logits, mask.float(), pos_weight=(1 - pos) / pos)
        opt.zero_grad()
        loss.backward()
        opt.step()
        t2 = time.perf_counter()
        t_aug.append(t1 - t0)
        t_net.append(t2 - t1)
        losses.append(float(loss.detach()))
        ious.append(iou(logits.detach(), mask))
        if batch0 is None:
            batch0 = (x[:, :1].clone(), mask.clone(), dict(aug._params))
        if step % 10 == 0 or step == steps - 1:
            log(f"step {step:4d}  loss {losses[-1]:.3f}  IoU {ious[-1]:.2f}  "
                f"augmentation {1e3 * t_aug[-1]:.0f} ms  net {1e3 * t_net[-1]:.0f} ms")
    share = statistics.median(t_aug) / (statistics.median(t_aug) + statistics.median(t_net))
    return dict(losses=losses, ious=ious, t_aug=t_aug, t_net=t_net, share=share, batch0=batch0)


def save_batch_grid(counts: torch.Tensor, mask: torch.Tensor, params: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    disp = ToDisplay(1.0, 99.0)(counts)  # what a person sees on the camera's monitor
    n = counts.shape[0]
    cols = min(4, n)
    rows = (n + cols - 1) // cols
    h, w = counts.shape[-2:]
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols, 3.4 * rows * h / w + 0.5), squeeze=False)
    for i, ax in enumerate(axes.flat):
        ax.axis("off")
        if i >= n:
            continue
        ax.imshow(disp[i, 0].numpy(), cmap="gray", vmin=0, vmax=255)
        ax.contour(mask[i, 0].float().numpy(), levels=[0.5], colors="tab:red", linewidths=0.6)
        ax.set_title(f"W {float(params['wind_speed'][i]):.1f} m/s  T_sea {float(params['sea_temperature'][i]):.1f} K  "
                     f"T_air - T_sea {float(params['air_sea_difference'][i]):+.1f} K\n"
                     f"h {float(params['altitude_m'][i]):.0f} m  pitch {float(params['pitch_deg'][i]):.1f}°", fontsize=7)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--height", type=int, default=128)
    ap.add_argument("--width", type=int, default=160)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "outputs" / "train")
    a = ap.parse_args()
    r = train(a.steps, a.batch, a.height, a.width, a.seed)
    counts, mask, params = r["batch0"]
    save_batch_grid(counts, mask, params, a.out / "batch.png")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3))
    ax.plot(r["losses"], label="loss")
    ax.plot(r["ious"], label="IoU")
    ax.set_xlabel("step")
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.out / "curves.png", dpi=110)
    plt.close(fig)
    k = max(1, len(r["losses"]) // 5)
    print(f"loss first {k} steps {statistics.mean(r['losses'][:k]):.3f} -> last {k} {statistics.mean(r['losses'][-k:]):.3f}; "
          f"IoU {statistics.mean(r['ious'][:k]):.2f} -> {statistics.mean(r['ious'][-k:]):.2f}")
    print(f"median per step: augmentation {1e3 * statistics.median(r['t_aug']):.0f} ms, net {1e3 * statistics.median(r['t_net']):.0f} ms "
          f"-> sea generation is {100 * r['share']:.0f} % of a step ({a.batch}×{a.height}×{a.width})")
    print(f"wrote {a.out / 'batch.png'} and {a.out / 'curves.png'}")


if __name__ == "__main__":
    main()
