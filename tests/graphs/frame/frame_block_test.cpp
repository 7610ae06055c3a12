#include "graphs/frame/frame_block.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace orthoflow::graphs {
namespace {

TEST(FrameBlock, CapacityIsTheLargestThatFits) {
  for (std::size_t capacity : {0UL, 1UL, 15UL, 16UL, 17UL, 1000UL, 640UL * 480UL}) {
    const std::size_t bytes = FrameBlock::bytes_for(capacity);
    const std::size_t fits = FrameBlock::capacity_for(bytes);
    EXPECT_GE(fits, capacity);  // alignment padding may leave room for a few more points
    EXPECT_LE(FrameBlock::bytes_for(fits), bytes);
    EXPECT_GT(FrameBlock::bytes_for(fits + 1), bytes);
  }
  EXPECT_LE(FrameBlock::bytes_for(640 * 480), 15'000'000U);  // graphs/tabletop.yaml's block size
}

TEST(FrameBlock, RegionsAreAlignedAndDisjoint) {
  const std::size_t capacity = 1000;
  const std::size_t bytes = FrameBlock::bytes_for(capacity);
  struct alignas(64) Line {
    std::byte b[64];
  };
  std::vector<Line> lines((bytes + 63) / 64);
  auto* memory = reinterpret_cast<std::byte*>(lines.data());
  const FrameBlock block({memory, bytes}, capacity);
  const auto* begin = memory;
  const auto* end = begin + bytes;
  auto inside = [&](const void* p, std::size_t n) {
    const auto* b = static_cast<const std::byte*>(p);
    return b >= begin && b + n <= end && reinterpret_cast<std::uintptr_t>(b) % 64 == 0;
  };
  EXPECT_TRUE(inside(&block.state(), sizeof(FrameState)));
  EXPECT_TRUE(inside(block.voxels().z.data(), capacity * 4));
  EXPECT_TRUE(inside(block.object_points().x.data(), capacity * 4));
  EXPECT_TRUE(inside(block.descriptor(MAX_OBJECTS - 1).data(), MAX_DESCRIPTOR * 4));
  EXPECT_LE(reinterpret_cast<const std::byte*>(block.raw().data() + block.raw().size()),
            reinterpret_cast<const std::byte*>(&block.state()));
  // the raw region holds a full frame of that capacity with every optional field
  EXPECT_GE(block.raw().size(),
            engine::frame_payload_bytes(static_cast<std::uint32_t>(capacity), 1,
                                        engine::FRAME_FIELD_RGB | engine::FRAME_FIELD_LABEL));
}

TEST(FrameBlock, ABlockSizedForALargerRoomGivesEveryObjectThatRoom) {
  EXPECT_EQ(descriptor_room_for(0), MAX_DESCRIPTOR);
  EXPECT_EQ(descriptor_room_for(MAX_DESCRIPTOR), MAX_DESCRIPTOR);
  EXPECT_EQ(descriptor_room_for(MAX_DESCRIPTOR + 1), MAX_DESCRIPTOR + DESCRIPTOR_ALIGN);
  const std::size_t set = 1 + 128 * 153;  // a set of 128 spin images of width 8: 19,585 floats
  const std::size_t room = descriptor_room_for(set);
  EXPECT_EQ(room, 19'600U);
  const std::size_t capacity = 1000;
  const std::size_t bytes = FrameBlock::bytes_for(capacity, room);
  EXPECT_EQ(bytes - FrameBlock::bytes_for(capacity), MAX_OBJECTS * (room - MAX_DESCRIPTOR) * 4);
  EXPECT_EQ(FrameBlock::room_in(bytes, capacity), room);
  EXPECT_EQ(FrameBlock::room_in(bytes - 1, capacity), room - DESCRIPTOR_ALIGN);
  EXPECT_EQ(FrameBlock::room_in(FrameBlock::bytes_for(capacity), capacity), MAX_DESCRIPTOR);
  EXPECT_EQ(FrameBlock::room_in(100, capacity), 0U);  // not even the other regions
  EXPECT_GE(FrameBlock::capacity_for(bytes, room), capacity);
  EXPECT_LT(FrameBlock::capacity_for(bytes, room), FrameBlock::capacity_for(bytes));
  struct alignas(64) Line {
    std::byte b[64];
  };
  std::vector<Line> lines(bytes / 64);
  auto* memory = reinterpret_cast<std::byte*>(lines.data());
  const FrameBlock block({memory, bytes}, capacity);
  EXPECT_EQ(block.descriptor_room(), room);
  const auto last = block.descriptor(MAX_OBJECTS - 1);
  EXPECT_EQ(last.size(), room);
  EXPECT_EQ(reinterpret_cast<const std::byte*>(last.data() + last.size()), memory + bytes);
  EXPECT_EQ(block.descriptor(1).data(), block.descriptor(0).data() + room);
  // the regions before the descriptors do not move with the room
  std::vector<Line> small(FrameBlock::bytes_for(capacity) / 64);
  const FrameBlock good({reinterpret_cast<std::byte*>(small.data()), small.size() * 64}, capacity);
  EXPECT_EQ(good.descriptor_room(), MAX_DESCRIPTOR);
  EXPECT_EQ(reinterpret_cast<const std::byte*>(block.descriptor(0).data()) - memory,
            reinterpret_cast<const std::byte*>(good.descriptor(0).data()) -
                reinterpret_cast<const std::byte*>(small.data()));
}

TEST(FrameError, TheFirstErrorAFrameMeetsIsTheOneItReports) {
  FrameError e;
  EXPECT_TRUE(e.empty());
  EXPECT_FALSE(e.set(FrameError::Code::NONE, "source"));
  EXPECT_TRUE(e.set(FrameError::Code::FILE_UNREADABLE, "source", 3));
  e.detail.assign("a.pcd: truncated");
  const kernels::SegmentationError later{kernels::SegmentationError::Code::NO_PLANE, 1, 0.0, 0, 0};
  EXPECT_FALSE(e.set("table", later));  // a later stage does not overwrite it
  EXPECT_EQ(e.code, FrameError::Code::FILE_UNREADABLE);
  EXPECT_EQ(e.to_string(), "source: FILE_UNREADABLE: a.pcd: truncated");
  FrameError seg;
  EXPECT_TRUE(seg.set("table", later));
  EXPECT_EQ(seg.segmentation.code, kernels::SegmentationError::Code::NO_PLANE);
  EXPECT_NE(seg.to_string().find("table: SEGMENTATION: segmentation: NO_PLANE: ransac_plane"),
            std::string::npos)
      << seg.to_string();
  for (const auto c : {FrameError::Code::NONE, FrameError::Code::FRAME_TOO_LARGE,
                       FrameError::Code::FILE_UNREADABLE, FrameError::Code::INVALID_FRAME,
                       FrameError::Code::SEGMENTATION}) {
    EXPECT_NE(FrameError::name(c), "UNKNOWN");
  }
  FrameError big;
  EXPECT_TRUE(big.set(FrameError::Code::FRAME_TOO_LARGE, "source", 0, 400000.0));
  EXPECT_EQ(big.to_string(), "source: FRAME_TOO_LARGE: 400000 points");
  FrameError invalid;
  EXPECT_TRUE(invalid.set(FrameError::Code::INVALID_FRAME, "preprocess", 2));
  EXPECT_EQ(invalid.to_string(), "preprocess: INVALID_FRAME: frame error 2");
}

TEST(FrameBlock, TextTruncatesAndTerminates) {
  Text t;
  EXPECT_TRUE(t.empty());
  t.assign("mug");
  EXPECT_EQ(t.view(), "mug");
  t.assign(std::string(200, 'x'));
  EXPECT_EQ(t.view().size(), core::TEXT_MAX_BYTES);
}

}  // namespace
}  // namespace orthoflow::graphs
