#!/usr/bin/env python3
"""Writes constant_yolo.onnx: a tiny ONNX graph whose output does not depend on the image.

It has the shape of a YOLOv5-style export (input 1x3x320x320, output 1 x N x (5 + 80),
rows [cx, cy, w, h, objectness, 80 class scores] in input pixels), so the ONNX decoding
of devslam::detect::YoloDetector (scaling, objectness x class score, class filter, NMS)
can be tested against known boxes without shipping a trained ONNX model.
Run with Debian's python3-onnx:  /usr/bin/python3 make_constant_yolo_onnx.py
"""
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

N_CLASSES, PERSON, DOG = 80, 0, 16
rows = np.zeros((4, 5 + N_CLASSES), dtype=np.float32)
rows[0, :5] = [160, 160, 64, 192, 0.9]; rows[0, 5 + PERSON] = 0.8   # person, score 0.72
rows[1, :5] = [164, 160, 64, 192, 0.9]; rows[1, 5 + PERSON] = 0.5   # overlaps row 0: NMS
rows[2, :5] = [80, 80, 40, 40, 0.95];   rows[2, 5 + DOG] = 0.9      # a dog: not a wanted class
rows[3, :5] = [280, 60, 30, 60, 0.9];   rows[3, 5 + PERSON] = 0.3   # 0.9 x 0.3 < 0.35

x = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, 320, 320])
y = helper.make_tensor_value_info("output", TensorProto.FLOAT, [1, 4, 5 + N_CLASSES])
init = [
    numpy_helper.from_array(np.zeros((rows.size, 3), np.float32), "W"),  # image has no effect
    numpy_helper.from_array(rows.reshape(-1), "B"),
    numpy_helper.from_array(np.array([1, 4, 5 + N_CLASSES], np.int64), "shape"),
]
nodes = [
    helper.make_node("GlobalAveragePool", ["images"], ["pooled"]),
    helper.make_node("Flatten", ["pooled"], ["flat"], axis=1),
    helper.make_node("Gemm", ["flat", "W", "B"], ["rows"], transB=1),
    helper.make_node("Reshape", ["rows", "shape"], ["output"]),
]
graph = helper.make_graph(nodes, "constant_yolo", [x], [y], init)
model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 11)],
                          producer_name="devslam tests")
onnx.checker.check_model(model)
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "constant_yolo.onnx")
onnx.save(model, out)
print("wrote", out, os.path.getsize(out), "bytes")
