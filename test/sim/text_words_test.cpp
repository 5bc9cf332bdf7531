#include "laser_dpslam/sim/text_words.h"

#include <gtest/gtest.h>

using laser_dpslam::lineWords;

TEST(TextWords, WordsBeforeTheCommentSeparatedByWhiteSpace) {
  EXPECT_EQ(lineWords("1.5  2\t0.3"), (std::vector<std::string>{"1.5", "2", "0.3"}));
  EXPECT_EQ(lineWords("wall 0 0 1 1  # the north wall"), (std::vector<std::string>{"wall", "0", "0", "1", "1"}));
  EXPECT_TRUE(lineWords("# only a comment").empty());
  EXPECT_TRUE(lineWords("   ").empty());
  EXPECT_TRUE(lineWords("").empty());
  EXPECT_EQ(lineWords("a#b"), (std::vector<std::string>{"a"}));
}
