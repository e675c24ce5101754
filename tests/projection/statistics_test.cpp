#include "facet/projection/statistics.hpp"

#include <gtest/gtest.h>

namespace facet {
namespace {

TEST(Statistics, MedianOfOddEvenAndNoValues) {
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(median({4.0}), 4.0);
  EXPECT_EQ(median({9.0, 1.0, 5.0}), 5.0);
  EXPECT_EQ(median({7.0, 1.0, 3.0, 100.0}), 5.0);  // (3 + 7) / 2
  EXPECT_EQ(median({2.0, 2.0, 2.0, 2.0}), 2.0);
}

}  // namespace
}  // namespace facet
