// The fast depthwise / pointwise convolutions against OpenCV's own layer, on random weights
// and inputs, and on the shipped detector.
#include <devslam/detect/FastConvolution.h>
#include <devslam/detect/YoloDetector.h>

#include <gtest/gtest.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <string>
#include <vector>

using namespace devslam;

namespace {
struct ConvCase {
    int cin, cout, k, stride, pad, group, h, w;
    bool bias, batch_norm;
    float slope;  // < 0: no ReLU after the convolution
};

std::string describe(const ConvCase& c) {
    return "cin " + std::to_string(c.cin) + " cout " + std::to_string(c.cout) + " k " +
           std::to_string(c.k) + " stride " + std::to_string(c.stride) + " pad " +
           std::to_string(c.pad) + " group " + std::to_string(c.group) + " input " +
           std::to_string(c.h) + "x" + std::to_string(c.w) + (c.bias ? " bias" : "") +
           (c.batch_norm ? " batchnorm" : "") +
           (c.slope >= 0 ? " relu " + std::to_string(c.slope) : "");
}

// convolution [-> batch norm] [-> ReLU], weights drawn from a fixed seed.
// `bias_term`: whether the parameters say so beside the bias blob (OpenCV's ONNX importer
// pushes the blob and leaves the key out).
cv::dnn::Net makeNet(const ConvCase& c, bool bias_term_key = true) {
    cv::RNG rng(1234);
    cv::dnn::Net net;
    cv::dnn::LayerParams conv;
    conv.set("kernel_size", c.k);
    conv.set("stride", c.stride);
    conv.set("pad", c.pad);
    conv.set("num_output", c.cout);
    conv.set("group", c.group);
    if (bias_term_key) conv.set("bias_term", c.bias);
    cv::Mat w(std::vector<int>{c.cout, c.cin / c.group, c.k, c.k}, CV_32F);
    rng.fill(w, cv::RNG::UNIFORM, -1.0, 1.0);
    conv.blobs.push_back(w);
    if (c.bias) {
        cv::Mat b(1, c.cout, CV_32F);
        rng.fill(b, cv::RNG::UNIFORM, -1.0, 1.0);
        conv.blobs.push_back(b);
    }
    net.addLayerToPrev("conv", "Convolution", conv);
    if (c.batch_norm) {
        cv::dnn::LayerParams bn;
        cv::Mat mean(1, c.cout, CV_32F), var(1, c.cout, CV_32F), gamma(1, c.cout, CV_32F),
            beta(1, c.cout, CV_32F);
        rng.fill(mean, cv::RNG::UNIFORM, -0.5, 0.5);
        rng.fill(var, cv::RNG::UNIFORM, 0.5, 2.0);
        rng.fill(gamma, cv::RNG::UNIFORM, 0.5, 1.5);
        rng.fill(beta, cv::RNG::UNIFORM, -0.5, 0.5);
        bn.blobs = {mean, var, gamma, beta};
        bn.set("has_weight", true);
        bn.set("has_bias", true);
        bn.set("eps", 1e-5);
        net.addLayerToPrev("bn", "BatchNorm", bn);
    }
    if (c.slope >= 0) {
        cv::dnn::LayerParams relu;
        relu.set("negative_slope", c.slope);
        net.addLayerToPrev("relu", "ReLU", relu);
    }
    return net;
}

cv::Mat randomInput(const ConvCase& c) {
    cv::Mat x(std::vector<int>{2, c.cin, c.h, c.w}, CV_32F);  // two images: batches work
    cv::RNG(99).fill(x, cv::RNG::UNIFORM, -1.0, 1.0);
    return x;
}

cv::Mat run(cv::dnn::Net& net, const cv::Mat& x) {
    net.setInput(x);
    return net.forward().clone();
}

class FastConvolution : public ::testing::Test {
  protected:
    void SetUp() override {
        if (!detect::fastConvolutionsSupported())
            GTEST_SKIP() << "this CPU has no AVX2/FMA: the fast convolutions are not used here";
    }
};
}  // namespace

TEST_F(FastConvolution, DepthwiseAndPointwiseMatchOpenCv) {
    const std::vector<ConvCase> cases{
        // depthwise 3x3, stride 1 and 2, rows wider and narrower than a 32-output group,
        // widths that are no multiple of 8
        {16, 16, 3, 1, 1, 16, 41, 67, false, true, 0.1f},
        {12, 12, 3, 2, 1, 12, 40, 40, true, false, -1.f},
        {9, 9, 3, 2, 1, 9, 23, 19, false, true, 0.f},
        {20, 20, 3, 1, 1, 20, 10, 10, false, true, -1.f},
        {7, 7, 3, 1, 0, 7, 5, 13, true, false, 0.f},
        // depthwise 5x5 and 7x7, as in Yolo-Fastest's head
        {8, 8, 5, 1, 2, 8, 20, 20, false, true, 0.1f},
        {6, 6, 5, 2, 2, 6, 17, 30, true, false, -1.f},
        {5, 5, 7, 1, 3, 5, 12, 9, false, false, 1.f},
        // pointwise: output channels no multiple of 4, pixels no multiple of 24
        {8, 48, 1, 1, 0, 1, 40, 40, false, true, 0.1f},
        {17, 5, 1, 1, 0, 1, 10, 10, true, false, 0.f},
        {3, 255, 1, 1, 0, 1, 7, 9, true, false, -1.f},
        {144, 96, 1, 1, 0, 1, 20, 20, false, true, -1.f},
    };
    for (const auto& c : cases) {
        SCOPED_TRACE(describe(c));
        cv::dnn::Net reference = makeNet(c);
        cv::dnn::Net fast = detect::withFastConvolutions([&] { return makeNet(c); });
        ASSERT_TRUE(detect::isFastConvolution(fast.getLayer("conv")));
        ASSERT_FALSE(detect::isFastConvolution(reference.getLayer("conv")));
        const cv::Mat x = randomInput(c);
        const cv::Mat a = run(reference, x);
        const cv::Mat b = run(fast, x);
        ASSERT_EQ(a.size, b.size);
        // Sums of up to 144 products of values in [-1, 1], in another order.
        const double scale = 1.0 + cv::norm(a, cv::NORM_INF);
        EXPECT_LE(cv::norm(a, b, cv::NORM_INF), 1e-5 * scale)
            << "largest output " << scale - 1.0;
    }
}

// A network set up again (another input size: OpenCV allocates and fuses its layers anew)
// gives the same output as OpenCV's own layer: the batch norm fused into the weights the
// first time was fused a second time, or, with a ReLU, run again after them.
TEST_F(FastConvolution, AnotherInputSizeFusesTheBatchNormOnce) {
    const std::vector<ConvCase> cases{{16, 16, 3, 1, 1, 16, 20, 20, false, true, -1.f},
                                      {16, 16, 3, 1, 1, 16, 20, 20, true, true, 0.1f},
                                      {8, 24, 1, 1, 0, 1, 20, 20, false, true, -1.f},
                                      {8, 24, 1, 1, 0, 1, 20, 20, true, true, 0.f}};
    for (const auto& c : cases) {
        SCOPED_TRACE(describe(c));
        cv::dnn::Net reference = makeNet(c);
        cv::dnn::Net fast = detect::withFastConvolutions([&] { return makeNet(c); });
        ConvCase other = c;
        other.h = 24;
        other.w = 32;
        for (const ConvCase& size : {c, other, c}) {
            SCOPED_TRACE("input " + std::to_string(size.h) + "x" + std::to_string(size.w));
            const cv::Mat x = randomInput(size);
            const cv::Mat a = run(reference, x);
            const cv::Mat b = run(fast, x);
            ASSERT_EQ(a.size, b.size);
            const double scale = 1.0 + cv::norm(a, cv::NORM_INF);
            EXPECT_LE(cv::norm(a, b, cv::NORM_INF), 1e-5 * scale);
        }
    }
}

// The ONNX importer's convolutions: a bias blob and no "bias_term" key. OpenCV's layer
// adds the blob (hasBias() is blobs.size() >= 2); so must ours (it dropped the bias).
TEST_F(FastConvolution, ABiasBlobWithoutTheBiasTermKeyIsAdded) {
    const std::vector<ConvCase> cases{{12, 12, 3, 1, 1, 12, 20, 20, true, false, -1.f},
                                      {17, 5, 1, 1, 0, 1, 10, 10, true, false, -1.f}};
    for (const auto& c : cases) {
        SCOPED_TRACE(describe(c));
        cv::dnn::Net reference = makeNet(c, false);
        cv::dnn::Net fast = detect::withFastConvolutions([&] { return makeNet(c, false); });
        ASSERT_TRUE(detect::isFastConvolution(fast.getLayer("conv")));
        const cv::Mat x = randomInput(c);
        const cv::Mat a = run(reference, x);
        const cv::Mat b = run(fast, x);
        ASSERT_EQ(a.size, b.size);
        EXPECT_LE(cv::norm(a, b, cv::NORM_INF), 1e-5 * (1.0 + cv::norm(a, cv::NORM_INF)));
    }
}

TEST_F(FastConvolution, SameOutputWithOneOrTwoThreads) {
    const ConvCase dw{24, 24, 3, 2, 1, 24, 33, 45, true, true, 0.1f};
    const ConvCase pw{40, 36, 1, 1, 0, 1, 30, 31, true, true, 0.1f};
    const int threads = cv::getNumThreads();
    for (const auto& c : {dw, pw}) {
        SCOPED_TRACE(describe(c));
        cv::dnn::Net net = detect::withFastConvolutions([&] { return makeNet(c); });
        const cv::Mat x = randomInput(c);
        cv::setNumThreads(1);
        const cv::Mat one = run(net, x);
        cv::setNumThreads(2);
        const cv::Mat two = run(net, x);
        cv::setNumThreads(threads);
        EXPECT_EQ(cv::norm(one, two, cv::NORM_INF), 0.0) << "each output is summed in one place";
    }
}

TEST_F(FastConvolution, OtherShapesStayOpenCvs) {
    const std::vector<ConvCase> others{
        {3, 16, 3, 2, 1, 1, 20, 20, false, false, -1.f},  // a full 3x3 convolution
        {8, 8, 3, 1, 1, 2, 12, 12, false, false, -1.f},   // grouped, not depthwise
        {8, 16, 1, 2, 0, 1, 12, 12, false, false, -1.f},  // 1x1 with stride 2
        {8, 8, 4, 1, 1, 8, 12, 12, false, false, -1.f},   // even depthwise kernel
    };
    for (const auto& c : others) {
        SCOPED_TRACE(describe(c));
        cv::dnn::Net reference = makeNet(c);
        cv::dnn::Net net = detect::withFastConvolutions([&] { return makeNet(c); });
        EXPECT_FALSE(detect::isFastConvolution(net.getLayer("conv")));
        const cv::Mat x = randomInput(c);
        EXPECT_EQ(cv::norm(run(reference, x), run(net, x), cv::NORM_INF), 0.0);
    }
}

TEST_F(FastConvolution, OnlyTheNetworkReadInsideGetsThem) {
    const ConvCase c{16, 16, 3, 1, 1, 16, 20, 20, false, false, -1.f};
    cv::dnn::Net inside = detect::withFastConvolutions([&] { return makeNet(c); });
    cv::dnn::Net after = makeNet(c);
    EXPECT_EQ(detect::countFastConvolutions(inside), 1);
    EXPECT_EQ(detect::countFastConvolutions(after), 0)
        << "the registration must end with withFastConvolutions";
    // An exception in the reader also ends it.
    EXPECT_THROW((void)detect::withFastConvolutions(
                     []() -> cv::dnn::Net { throw std::runtime_error("reader failed"); }),
                 std::runtime_error);
    cv::dnn::Net later = makeNet(c);
    EXPECT_EQ(detect::countFastConvolutions(later), 0);
}

TEST_F(FastConvolution, YoloFastestXlGivesTheSameDetections) {
    const std::string root = DEVSLAM_SOURCE_DIR;
    detect::YoloDetector::Options o;
    o.classes = {"person", "dog", "horse"};
    o.fast_convolutions = false;
    detect::YoloDetector opencv(o);
    o.fast_convolutions = true;
    detect::YoloDetector fast(o);
    std::size_t found = 0;
    for (const std::string name : {"person.jpg", "dog.jpg"}) {
        SCOPED_TRACE(name);
        const cv::Mat image = cv::imread(root + "/data/images/" + name);
        ASSERT_FALSE(image.empty());
        const auto a = opencv.detect(image);
        const auto b = fast.detect(image);
        ASSERT_EQ(a.size(), b.size());
        found += a.size();
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_EQ(a[i].class_id, b[i].class_id);
            EXPECT_NEAR(a[i].score, b[i].score, 1e-4f);
            EXPECT_GE(detect::iou(a[i].box, b[i].box), 0.999f) << a[i].box << " " << b[i].box;
        }
    }
    EXPECT_GE(found, 3u) << "person.jpg holds a person, a dog and a horse";
}
