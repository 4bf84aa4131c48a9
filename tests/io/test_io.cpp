#include <devslam/io/TumReader.h>
#include <gtest/gtest.h>
TEST(Placeholder, Builds) { SUCCEED(); }
