#!/usr/bin/python3
"""Trains sba-slam's DI-Net-style saliency model on salient datasets made by
`sba-slam saliency make-dataset`, evaluates it against two baselines on held-out datasets, and
exports it to ONNX for OpenCV dnn.

Run with Debian's /usr/bin/python3 (torch 1.13, numpy, opencv). Example:
  nice -n 10 /usr/bin/python3 python/train_saliency.py \
      --train /tmp/sal/ds/train_* --holdout /tmp/sal/ds/test_* --out models --minutes 12

Writes to --out: saliency_model.onnx, saliency_model.json (input size, output convention, the
C++/PyTorch check's file names), saliency_metrics.json (training log and held-out metrics),
saliency_check_logits.f32 (PyTorch's logits on the fixed check input, see check_input()).

With --evaluate-only MODEL.onnx nothing is trained: the ONNX model (through OpenCV dnn, as the C++
side runs it) and the two baselines are scored on --holdout, e.g. to compare the shipped model
with a candidate on the same frames:
  /usr/bin/python3 python/train_saliency.py --evaluate-only models/saliency_model.onnx \
      --holdout /tmp/sal/ds/test_* [--train /tmp/sal/ds/train_*] [--json scores.json]
"""

import argparse
import json
import os
import sys
import time

import cv2
import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from saliency_metrics import auc_judd, cc, kld, nss  # noqa: E402


# ---------------------------------------------------------------------------------------------
# Model: encoder (stride 8) -> dilated inception module -> light decoder -> bilinear x8.


def conv_bn(cin, cout, stride=1, dilation=1):
    return nn.Sequential(
        nn.Conv2d(cin, cout, 3, stride=stride, padding=dilation, dilation=dilation, bias=False),
        nn.BatchNorm2d(cout),
        nn.ReLU(inplace=True),
    )


class DilatedInception(nn.Module):
    """DI-Net's dilated inception module: parallel 3x3 convolutions at several dilation rates see
    context at several scales; their outputs are concatenated and mixed by a 1x1 convolution."""

    def __init__(self, cin, branch, rates, cout):
        super().__init__()
        self.branches = nn.ModuleList([conv_bn(cin, branch, dilation=r) for r in rates])
        self.mix = nn.Sequential(nn.Conv2d(branch * len(rates), cout, 1, bias=False),
                                 nn.BatchNorm2d(cout), nn.ReLU(inplace=True))

    def forward(self, x):
        return self.mix(torch.cat([b(x) for b in self.branches], dim=1))


class SaliencyNet(nn.Module):
    """Stride-8 encoder (grayscale in), a dilated inception module at 1/8 resolution, a 3x3 + 1x1
    decoder and a bilinear x8 upsampling to the input size (logits out). About 26 M multiply-adds
    at 320x96."""

    def __init__(self, width=8):
        super().__init__()
        w = width
        self.encoder = nn.Sequential(
            conv_bn(1, w, stride=2),
            conv_bn(w, 2 * w, stride=2), conv_bn(2 * w, 2 * w),
            conv_bn(2 * w, 4 * w, stride=2), conv_bn(4 * w, 4 * w),
        )
        self.dim = DilatedInception(4 * w, 2 * w, (1, 2, 4, 8), 4 * w)
        self.decoder = nn.Sequential(conv_bn(4 * w, 2 * w), nn.Conv2d(2 * w, 1, 1))

    def forward(self, x):
        h, w = x.shape[2], x.shape[3]
        z = self.decoder(self.dim(self.encoder(x)))
        return F.interpolate(z, size=(h, w), mode="bilinear", align_corners=False)


def log_density(logits):
    """Per-image log-softmax over all pixels: the predicted fixation distribution."""
    n = logits.shape[0]
    return F.log_softmax(logits.reshape(n, -1), dim=1).reshape(logits.shape)


def saliency_loss(logits, target):
    """KL divergence (target || prediction) plus (1 - correlation coefficient)."""
    n = logits.shape[0]
    log_p = log_density(logits).reshape(n, -1)
    p = log_p.exp()
    q = target.reshape(n, -1)
    q = q / q.sum(dim=1, keepdim=True).clamp_min(1e-12)
    kl = (q * (torch.log(q.clamp_min(1e-12)) - log_p)).sum(dim=1)
    pc = p - p.mean(dim=1, keepdim=True)
    qc = q - q.mean(dim=1, keepdim=True)
    corr = (pc * qc).sum(dim=1) / (pc.norm(dim=1) * qc.norm(dim=1)).clamp_min(1e-12)
    return (kl + 1.0 - corr).mean()


def saturated_map_loss(logits, target, features, tau, floor=0.01):
    """How far the map Salient BA reads, S_sat = min(1, map / (255 tau)) with map = 255 exp(z - max
    z), is from the target's own S_sat, in log units, where the geometric features are (ORB
    keypoints lie on them, cars' included): KL and CC score the density, and a density close
    overall can still saturate on a near car's edge. One-sided where the target saturates (any
    value at or above 1 saturates alike); S_sat below `floor` counts as `floor` (weight b alike).
    Averaged with the unfiltered feature map as the pixel weight."""
    n = logits.shape[0]
    z = logits.reshape(n, -1)
    u = z - z.max(dim=1, keepdim=True).values - float(np.log(tau))
    q = target.reshape(n, -1)
    v = torch.log((q / q.max(dim=1, keepdim=True).values.clamp_min(1e-12)).clamp_min(1e-12))
    log_floor = float(np.log(floor))
    v = (v - float(np.log(tau))).clamp_min(log_floor)
    zero = torch.zeros_like(u)
    too_low = torch.where(v > log_floor, torch.relu(v.clamp_max(0.0) - u), zero)
    too_high = torch.where(v < 0.0, torch.relu(u - v), zero)
    w = features.reshape(n, -1)
    w = w / w.sum(dim=1, keepdim=True).clamp_min(1e-12)
    return ((too_low + too_high) * w).sum(dim=1).mean()


# ---------------------------------------------------------------------------------------------
# Data


def read_dataset(folder, size):
    """Images (model input size, [0, 1]), target maps at the same size, and the full-resolution
    ground truth (map, fixations, unfiltered map) for evaluation."""
    rows = []
    with open(os.path.join(folder, "dataset.csv")) as f:
        header = f.readline().strip().split(",")
        for line in f:
            rows.append(dict(zip(header, line.strip().split(","))))
    items = []
    for r in rows:
        gray = cv2.imread(r["image"], cv2.IMREAD_GRAYSCALE)
        gt = cv2.imread(os.path.join(folder, r["map"]), cv2.IMREAD_GRAYSCALE)
        fix = cv2.imread(os.path.join(folder, r["fixations"]), cv2.IMREAD_GRAYSCALE)
        raw = cv2.imread(os.path.join(folder, r["unfiltered"]), cv2.IMREAD_GRAYSCALE)
        if gray is None or gt is None or fix is None or raw is None:
            sys.exit(f"train_saliency.py: error: {folder}: unreadable sample {r['map']}")
        items.append({
            "input": cv2.resize(gray, size, interpolation=cv2.INTER_AREA).astype(np.float32) / 255,
            "target": cv2.resize(gt, size, interpolation=cv2.INTER_AREA).astype(np.float32) / 255,
            "features": cv2.resize(raw, size, interpolation=cv2.INTER_AREA).astype(np.float32) / 255,
            "gt": gt.astype(np.float64) / 255, "fixations": fix > 0,
            "unfiltered": raw.astype(np.float64) / 255, "name": folder + "/" + r["map"],
        })
    return items


def load(folders, size):
    items = []
    for folder in sorted(folders):
        items += read_dataset(folder, size)
    if not items:
        sys.exit("train_saliency.py: error: no samples in " + " ".join(folders))
    return items


def centre_bias(shape, sigma_fraction):
    h, w = shape
    y, x = np.mgrid[0:h, 0:w]
    return np.exp(-(((x - (w - 1) / 2) / (sigma_fraction * w)) ** 2 +
                    ((y - (h - 1) / 2) / (sigma_fraction * h)) ** 2) / 2)


# ---------------------------------------------------------------------------------------------


def predict_full(model, item):
    with torch.no_grad():
        z = model(torch.from_numpy(item["input"])[None, None])[0, 0].numpy().astype(np.float64)
    density = np.exp(z - z.max())
    h, w = item["gt"].shape
    return cv2.resize(density, (w, h), interpolation=cv2.INTER_LINEAR)


def onnx_predictor(path):
    """OpenCV dnn's prediction, upsampled to the ground truth's size like predict_full()."""
    net = cv2.dnn.readNetFromONNX(path)

    def predict(item):
        net.setInput(item["input"][None, None].astype(np.float32))
        z = net.forward()[0, 0].astype(np.float64)
        density = np.exp(z - z.max())
        h, w = item["gt"].shape
        return cv2.resize(density, (w, h), interpolation=cv2.INTER_LINEAR)

    return predict


def model_input_size(onnx_path, default):
    """The input size of the model's card (saliency_model.json beside it), else `default`."""
    card = os.path.join(os.path.dirname(os.path.abspath(onnx_path)), "saliency_model.json")
    if os.path.exists(card):
        with open(card) as f:
            return tuple(json.load(f)["input_size"])
    return default


def evaluate(predict, items, seed):
    rng = np.random.default_rng(seed)
    scores = {"CC": [], "KLD": [], "NSS": [], "AUC-Judd": []}
    for item in items:
        pred = predict(item)
        scores["CC"].append(cc(pred, item["gt"]))
        scores["KLD"].append(kld(pred, item["gt"]))
        scores["NSS"].append(nss(pred, item["fixations"]))
        scores["AUC-Judd"].append(auc_judd(pred, item["fixations"], rng))
    return {k: float(np.mean(v)) for k, v in scores.items()}


def best_centre_sigma(items):
    """The centre-bias baseline's width, chosen on the training set (fair to the baseline)."""
    best = None
    for s in (0.15, 0.2, 0.25, 0.3, 0.4, 0.5):
        score = np.mean([cc(centre_bias(i["gt"].shape, s), i["gt"]) for i in items[::4]])
        if best is None or score > best[1]:
            best = (s, score)
    return best[0]


def train(model, items, args, log):
    opt = torch.optim.Adam(model.parameters(), lr=args.lr, weight_decay=1e-5)
    inputs = torch.from_numpy(np.stack([i["input"] for i in items]))[:, None]
    targets = torch.from_numpy(np.stack([i["target"] for i in items]))[:, None]
    features = torch.from_numpy(np.stack([i["features"] for i in items]))[:, None]
    order_rng = np.random.default_rng(args.seed)
    start = time.time()
    epoch = 0
    while epoch < args.epochs and time.time() - start < args.minutes * 60:
        model.train()
        order = order_rng.permutation(len(items))
        flips = order_rng.random(len(items)) < 0.5
        total = 0.0
        for b in range(0, len(order), args.batch):
            idx = order[b:b + args.batch]
            x, t, g = inputs[idx].clone(), targets[idx].clone(), features[idx].clone()
            f = torch.from_numpy(flips[idx])
            x[f] = x[f].flip(-1)
            t[f] = t[f].flip(-1)
            g[f] = g[f].flip(-1)
            z = model(x)
            loss = saliency_loss(z, t)
            if args.saturated_weight > 0:
                loss = loss + args.saturated_weight * saturated_map_loss(z, t, g, args.saturation)
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
        epoch += 1
        log.append({"epoch": epoch, "loss": total / len(items), "seconds": time.time() - start})
        print(f"epoch {epoch}: loss {total / len(items):.4f} ({time.time() - start:.0f} s)",
              flush=True)
    return epoch


def check_input(size):
    """The fixed input of the C++/PyTorch check, computed the same way in the C++ test:
    u8[y][x] = (3x + 5y + 7((x*y) mod 17)) mod 256, divided by 255."""
    w, h = size
    y, x = np.mgrid[0:h, 0:w]
    return (((3 * x + 5 * y + 7 * ((x * y) % 17)) % 256).astype(np.float32) / np.float32(255))


def export(model, size, out, metrics):
    model.eval()
    w, h = size
    onnx_path = os.path.join(out, "saliency_model.onnx")
    torch.onnx.export(model, torch.zeros(1, 1, h, w), onnx_path, opset_version=11,
                      input_names=["image"], output_names=["logits"], do_constant_folding=True)
    with torch.no_grad():
        logits = model(torch.from_numpy(check_input(size))[None, None])[0, 0].numpy()
    logits.astype("<f4").tofile(os.path.join(out, "saliency_check_logits.f32"))
    card = {"input_size": [w, h], "input": "grayscale resized with INTER_AREA, divided by 255",
            "output": "logits z (1x1xHxW); map = 255 * exp(z - max z)", "opset": 11,
            "check_logits": "saliency_check_logits.f32"}
    with open(os.path.join(out, "saliency_model.json"), "w") as f:
        json.dump(card, f, indent=2)
    with open(os.path.join(out, "saliency_metrics.json"), "w") as f:
        json.dump(metrics, f, indent=2)


def evaluate_only(args, size):
    """Scores an exported model and the two baselines on --holdout; trains nothing."""
    if not os.path.exists(args.evaluate_only):
        sys.exit(f"train_saliency.py: error: {args.evaluate_only}: no such model file")
    size = model_input_size(args.evaluate_only, size)
    test_items = load(args.holdout, size)
    # The centre bias's width is chosen on --train when given (as in training), else the shipped
    # model's choice.
    sigma = best_centre_sigma(load(args.train, size)) if args.train else 0.4
    results = {
        "model": evaluate(onnx_predictor(args.evaluate_only), test_items, args.seed),
        "centre_bias": evaluate(lambda i: centre_bias(i["gt"].shape, sigma), test_items, args.seed),
        "unfiltered_features": evaluate(lambda i: i["unfiltered"], test_items, args.seed),
    }
    print(f"{args.evaluate_only}: {len(test_items)} held-out frames, centre sigma {sigma}")
    for name, r in results.items():
        print(f"{name:22s} " + "  ".join(f"{k} {v:.3f}" for k, v in r.items()))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"command": " ".join(sys.argv), "model": args.evaluate_only,
                       "holdout": sorted(args.holdout), "holdout_frames": len(test_items),
                       "centre_bias_sigma_fraction": sigma, "holdout_metrics": results}, f,
                      indent=2)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--train", nargs="+", help="make-dataset output folders")
    p.add_argument("--holdout", nargs="+", required=True, help="held-out make-dataset folders")
    p.add_argument("--out", help="folder for the model files (e.g. models)")
    p.add_argument("--evaluate-only", metavar="MODEL",
                   help="score this ONNX model and the baselines on --holdout; no training")
    p.add_argument("--json", help="with --evaluate-only: also write the scores to this file")
    p.add_argument("--input-size", default="320x96", help="WxH of the network input")
    p.add_argument("--width", type=int, default=8, help="channels of the first stage")
    p.add_argument("--epochs", type=int, default=200)
    p.add_argument("--minutes", type=float, default=12.0, help="training time budget")
    p.add_argument("--batch", type=int, default=8)
    p.add_argument("--lr", type=float, default=2e-3)
    p.add_argument("--seed", type=int, default=7)
    p.add_argument("--saturated-weight", type=float, default=0.0,
                   help="weight of the saturated-map term (saturated_map_loss); 0: KL + CC only")
    p.add_argument("--saturation", type=float, default=0.02,
                   help="the saturated-map term's tau (Saliency.saturation)")
    p.add_argument("--threads", type=int, default=1,
                   help="torch threads (more than the free cores only spin)")
    args = p.parse_args()
    if not args.evaluate_only and (not args.train or not args.out):
        p.error("--train and --out are required unless --evaluate-only is given")
    if not 0 <= args.saturated_weight < float("inf"):
        p.error(f"--saturated-weight must be finite and >= 0, got {args.saturated_weight}")
    if not 0 < args.saturation <= 1:
        p.error(f"--saturation must be in (0, 1], got {args.saturation}")

    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    torch.set_num_threads(args.threads)
    torch.use_deterministic_algorithms(True)
    size = tuple(int(v) for v in args.input_size.lower().split("x"))
    if args.evaluate_only:
        evaluate_only(args, size)
        return

    train_items, test_items = load(args.train, size), load(args.holdout, size)
    print(f"{len(train_items)} training and {len(test_items)} held-out frames at {size}", flush=True)
    model = SaliencyNet(args.width)
    log = []
    epochs = train(model, train_items, args, log)
    model.eval()

    sigma = best_centre_sigma(train_items)
    results = {
        "model": evaluate(lambda i: predict_full(model, i), test_items, args.seed),
        "centre_bias": evaluate(lambda i: centre_bias(i["gt"].shape, sigma), test_items, args.seed),
        "unfiltered_features": evaluate(lambda i: i["unfiltered"], test_items, args.seed),
    }
    for name, r in results.items():
        print(f"{name:22s} " + "  ".join(f"{k} {v:.3f}" for k, v in r.items()))
    metrics = {
        "command": " ".join(sys.argv), "train": sorted(args.train), "holdout": sorted(args.holdout),
        "train_frames": len(train_items), "holdout_frames": len(test_items),
        "input_size": list(size), "epochs": epochs, "seed": args.seed,
        "parameters": sum(p.numel() for p in model.parameters()),
        "centre_bias_sigma_fraction": sigma, "holdout_metrics": results, "training_log": log,
    }
    os.makedirs(args.out, exist_ok=True)
    export(model, size, args.out, metrics)


if __name__ == "__main__":
    main()
