#pragma once
/// Faster CPU kernels for the two convolution shapes a MobileNet-style detector such as
/// Yolo-Fastest is made of: depthwise k x k (stride 1 or 2) and pointwise 1 x 1, plugged into
/// cv::dnn as a layer that stands in for OpenCV's own "Convolution" layer for exactly those
/// shapes. Every other convolution and every other layer stays OpenCV's, and so do the model
/// readers, the graph and the batch-norm / ReLU fusion (the layer accepts both).
///
/// Why by hand: OpenCV 4.6 (Debian 12) runs a depthwise convolution one channel at a time,
/// about 2-4 GFLOP/s on this machine's AVX2 core, and a 1x1 convolution with few input
/// channels at 11-15 GFLOP/s; in Yolo-Fastest-XL those two took 27 of the 28 ms of a forward
/// pass (`Net::getPerfProfile`, docs/detect.md). No other library in Debian 12 runs darknet
/// models. The kernels need AVX2 and FMA and are selected at run time; on a CPU without them
/// OpenCV's layers are used unchanged.
///
/// Usage:
///   cv::dnn::Net net = detect::withFastConvolutions(
///       [&] { return cv::dnn::readNetFromDarknet(cfg, weights); });
#include <opencv2/dnn.hpp>

#include <functional>

namespace devslam::detect {

/// True when this CPU has the instructions the fast kernels use (AVX2 and FMA).
[[nodiscard]] bool fastConvolutionsSupported();

/// Calls `read` (which builds a network: readNetFromDarknet, readNetFromONNX, or layers added
/// by hand) with the fast layer registered for cv::dnn's "Convolution" type, then creates
/// every layer of the network while it is registered, and unregisters it. So only this
/// network gets the fast layers, and other cv::dnn users in the process are unaffected.
/// Calls from several threads are serialised. Without AVX2/FMA it only calls `read`.
[[nodiscard]] cv::dnn::Net withFastConvolutions(const std::function<cv::dnn::Net()>& read);

/// True when `layer` is one of the fast convolutions (for tests and benchmarks).
[[nodiscard]] bool isFastConvolution(const cv::Ptr<cv::dnn::Layer>& layer);

/// Number of the network's layers that are fast convolutions.
[[nodiscard]] int countFastConvolutions(cv::dnn::Net& net);

}  // namespace devslam::detect
