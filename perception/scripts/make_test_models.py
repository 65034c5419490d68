#!/usr/bin/env python3
"""Generates the tiny ONNX models the raw-frames tests run.

Each model is a few operators with fixed weights, so its output for a given
input is known in closed form and the tests can check every decoder and error
path through the real ONNX Runtime. Run from anywhere:

    python3 perception/scripts/make_test_models.py

Outputs go to perception/models/test/ (committed; re-running rewrites them
byte-identically). Needs the `onnx` and `numpy` packages.
"""
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "models", "test")
OPSET = [helper.make_opsetid("", 13)]


def save(graph, name):
    model = helper.make_model(graph, opset_imports=OPSET, producer_name="logicrag-test-models")
    model.ir_version = 7
    onnx.checker.check_model(model)
    path = os.path.join(OUT, name)
    with open(path, "wb") as f:
        f.write(model.SerializeToString())
    print("wrote", os.path.normpath(path))


def const(name, array):
    return numpy_helper.from_array(np.asarray(array, dtype=np.float32), name)


# Tiny GFL detector: input 1x3x32x32, strides 8 and 16 (16 and 4 cells),
# 3 classes, reg_max 3 (4 bins per side). The brightness m = mean(input)
# drives one cell: stride 8, cell 5 (x 1, y 1), class 2 gets score m; every
# side of that cell puts its distribution mass on bin 2 (so each distance is
# 2 x 8 = 16 px around the centre (12, 12)). All other scores are 0.
def gfl(name, size=32, nan=False):
    classes, bins = 3, 4
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, size, size])
    nodes = [helper.make_node("ReduceMean", ["image"], ["m"], axes=[1, 2, 3], keepdims=0)]
    inits = []
    outputs = []
    for stride in (8, 16):
        cells = (32 // stride) ** 2
        w = np.zeros((1, cells, classes), np.float32)
        if stride == 8:
            w[0, 5, 2] = 1.0
        inits.append(const(f"sw{stride}", w))
        nodes.append(helper.make_node("Mul", ["m", f"sw{stride}"], [f"scores{stride}"]))
        outputs.append(helper.make_tensor_value_info(f"scores{stride}", TensorProto.FLOAT, [1, cells, classes]))
    for stride in (8, 16):
        cells = (32 // stride) ** 2
        r = np.zeros((1, cells, 4 * bins), np.float32)
        r[0, :, 2::bins] = 30.0  # bin 2 of every side dominates
        if nan:
            r[0, 0, 0] = np.nan
        inits.append(const(f"rb{stride}", r))
        inits.append(const(f"z{stride}", 0.0))
        # reg = rb + 0 * m keeps the output data-dependent (no constant folding away the input).
        nodes.append(helper.make_node("Mul", ["m", f"z{stride}"], [f"mz{stride}"]))
        nodes.append(helper.make_node("Add", [f"rb{stride}", f"mz{stride}"], [f"reg{stride}"]))
        outputs.append(helper.make_tensor_value_info(f"reg{stride}", TensorProto.FLOAT, [1, cells, 4 * bins]))
    save(helper.make_graph(nodes, name, [x], outputs, inits), name + ".onnx")


# Tiny GFL detector with two boxes (for per-frame alignment, which needs
# more than one box): input 1x3x32x32, strides 8 and 16, 3 classes, reg_max
# 3. Stride-8 cells 5 (x 1, y 1) and 10 (x 2, y 2), class 2, both get score
# m = mean(input); every side puts its mass on bin 1 (8 px), so the boxes
# are [4, 20] and [12, 28] on both axes (IoU 0.14: NMS keeps both).
def gfl_two(name):
    classes, bins = 3, 4
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, 32, 32])
    nodes = [helper.make_node("ReduceMean", ["image"], ["m"], axes=[1, 2, 3], keepdims=0)]
    inits = []
    outputs = []
    for stride in (8, 16):
        cells = (32 // stride) ** 2
        w = np.zeros((1, cells, classes), np.float32)
        if stride == 8:
            w[0, 5, 2] = 1.0
            w[0, 10, 2] = 1.0
        inits.append(const(f"sw{stride}", w))
        nodes.append(helper.make_node("Mul", ["m", f"sw{stride}"], [f"scores{stride}"]))
        outputs.append(helper.make_tensor_value_info(f"scores{stride}", TensorProto.FLOAT, [1, cells, classes]))
    for stride in (8, 16):
        cells = (32 // stride) ** 2
        r = np.zeros((1, cells, 4 * bins), np.float32)
        r[0, :, 1::bins] = 30.0  # bin 1 of every side dominates
        inits.append(const(f"rb{stride}", r))
        inits.append(const(f"z{stride}", 0.0))
        nodes.append(helper.make_node("Mul", ["m", f"z{stride}"], [f"mz{stride}"]))
        nodes.append(helper.make_node("Add", [f"rb{stride}", f"mz{stride}"], [f"reg{stride}"]))
        outputs.append(helper.make_tensor_value_info(f"reg{stride}", TensorProto.FLOAT, [1, cells, 4 * bins]))
    save(helper.make_graph(nodes, name, [x], outputs, inits), name + ".onnx")


# A model whose only output has zero elements: Slice of the input past its end.
def empty():
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, 8, 8])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, 3, 8, 0])
    inits = [
        numpy_helper.from_array(np.array([8], np.int64), "starts"),
        numpy_helper.from_array(np.array([8], np.int64), "ends"),
        numpy_helper.from_array(np.array([3], np.int64), "axes"),
    ]
    nodes = [helper.make_node("Slice", ["image", "starts", "ends", "axes"], ["y"])]
    save(helper.make_graph(nodes, "empty", [x], [y], inits), "empty_output.onnx")


def conv1x1(name, in_ch, weights, bias, size=(8, 8)):
    h, w = size
    x = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, in_ch, h, w])
    out_ch = len(weights)
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [1, out_ch, h, w])
    W = np.asarray(weights, np.float32).reshape(out_ch, in_ch, 1, 1)
    inits = [const("W", W), const("B", bias)]
    nodes = [helper.make_node("Conv", ["image", "W", "B"], ["y"])]
    save(helper.make_graph(nodes, name, [x], [y], inits), name + ".onnx")


if __name__ == "__main__":
    os.makedirs(OUT, exist_ok=True)
    gfl("tiny_gfl")
    gfl("tiny_gfl_64", size=64)
    gfl("tiny_gfl_nan", nan=True)
    empty()
    # Segmentation (RGB, values 0-1): class 0 = 0.5 everywhere, class 1 = red,
    # class 2 = green. Red pixels -> 1, green -> 2, dark -> 0.
    conv1x1("tiny_seg", 3, [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [0.5, 0, 0])
    # Metric depth: the blue channel (the config scale turns it into metres).
    conv1x1("tiny_depth", 3, [[0, 0, 1]], [0.0])
    # Relative depth, 64x64 so a 64x64 frame maps pixel for pixel: the blue
    # channel (0-1) read as MiDaS-style inverse depth (relative units).
    conv1x1("tiny_rel_depth", 3, [[0, 0, 1]], [0.0], size=(64, 64))
    gfl_two("tiny_gfl_two")
    # Flow over two stacked RGB frames (previous, current): dx = 8 x (R_cur - R_prev), dy = 0.
    conv1x1("tiny_flow", 6, [[-8, 0, 0, 8, 0, 0], [0, 0, 0, 0, 0, 0]], [0.0, 0.0])
