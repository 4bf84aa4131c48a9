// Linked into every program and test only in the ThreadSanitizer build
// (DEVSLAM_SANITIZE_THREAD, cmake/devslam_add_library.cmake): OpenCV runs its parallel loops
// in the calling thread, so that the threads TSan checks are the programs' own.
#include <opencv2/core/utility.hpp>

namespace {
const bool kSerialOpenCV = (cv::setNumThreads(0), true);
}  // namespace
