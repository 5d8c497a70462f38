#!/usr/bin/env python3
"""Writes tests/data/depth_model_test.onnx, a stand-in for a user's monocular depth network
(MonoDepth and the like) with a known answer, for the C++ tests of Saliency.depth "model".

Input 1x3xHxW (RGB in [0, 1], H=32, W=64), output 1x1xHxW: 1 + 9 * (mean of the channels), so a
grey level g in [0, 255] maps to 1 + 9 g / 255. It is a fixed function, not a trained model.

    python3 python/make_test_depth_model.py tests/data/depth_model_test.onnx
"""
import sys

import torch


class KnownDepth(torch.nn.Module):
    def forward(self, image):
        return 1.0 + 9.0 * image.mean(dim=1, keepdim=True)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "tests/data/depth_model_test.onnx"
    torch.onnx.export(KnownDepth(), torch.zeros(1, 3, 32, 64), out, opset_version=11,
                      input_names=["image"], output_names=["depth"])


if __name__ == "__main__":
    main()
