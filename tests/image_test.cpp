// core/image.hpp: owned and borrowed pixels. A borrowed image reads the caller's memory (what the
// Python package hands the library for a NumPy array); its copies own theirs; moves keep either.
#include <gtest/gtest.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "kartograf/core/error.hpp"
#include "kartograf/core/image.hpp"

namespace kartograf {
namespace {

TEST(Image, BorrowedPixelsAreTheCallersMemory) {
  std::vector<std::uint16_t> memory(6 * 4);
  for (std::size_t i = 0; i < memory.size(); ++i) memory[i] = static_cast<std::uint16_t>(i);
  Image<std::uint16_t> view = Image<std::uint16_t>::borrow(memory.data(), 6, 4);
  EXPECT_TRUE(view.borrowed());
  EXPECT_EQ(view.data(), memory.data());
  EXPECT_EQ(view.size(), 24u);
  EXPECT_EQ(view(5, 3), 23);
  view(1, 0) = 100;  // writes reach the caller's memory
  EXPECT_EQ(memory[1], 100);
  EXPECT_EQ(view.pixels().data(), memory.data());
}

TEST(Image, CopiesOwnTheirPixelsAndMovesKeepThem) {
  std::vector<std::uint16_t> memory(3 * 2, 7);
  const Image<std::uint16_t> view = Image<std::uint16_t>::borrow(memory.data(), 3, 2);
  Image<std::uint16_t> copy = view;
  EXPECT_FALSE(copy.borrowed());
  EXPECT_NE(copy.data(), memory.data());
  EXPECT_EQ(copy(2, 1), 7);
  const std::uint16_t* owned = copy.data();
  Image<std::uint16_t> moved = std::move(copy);
  EXPECT_EQ(moved.data(), owned);  // the vector's buffer moves with it
  EXPECT_TRUE(copy.empty());       // NOLINT(bugprone-use-after-move): moved-from is empty
  Image<std::uint16_t> borrowed_move = Image<std::uint16_t>(view);
  borrowed_move = Image<std::uint16_t>::borrow(memory.data(), 3, 2);
  EXPECT_TRUE(borrowed_move.borrowed());
  EXPECT_EQ(borrowed_move.data(), memory.data());
  Image<std::uint16_t> assigned;
  assigned = view;
  EXPECT_FALSE(assigned.borrowed());
  EXPECT_EQ(assigned(0, 0), 7);
  EXPECT_THROW(Image<std::uint16_t>::borrow(memory.data(), -1, 2), Error);
}

}  // namespace
}  // namespace kartograf
