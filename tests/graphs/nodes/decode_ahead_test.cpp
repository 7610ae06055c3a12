// DecodeAhead with the pcd_source's decoding step: files come out in order, a bad file is a slot
// with its error (the next file still comes), the end is a slot marked end, loop starts over, and a
// slot is reused only after release.
#include <gtest/gtest.h>

#include <unistd.h>
#include <fstream>

#include "formats/pcd_io.hpp"
#include "graphs/nodes/decode_ahead.hpp"
#include "graphs/nodes/source_nodes.hpp"

namespace orthoflow::graphs {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> write_files(const fs::path& dir) {
  fs::create_directories(dir);
  std::vector<fs::path> files;
  for (int k = 0; k < 3; ++k) {
    kernels::PointCloud c;
    c.resize_unorganized(static_cast<std::size_t>(k + 1));
    files.push_back(dir / ("f" + std::to_string(k) + ".pcd"));
    EXPECT_TRUE(formats::write_pcd(c, files.back()));
  }
  files.insert(files.begin() + 1, dir / "bad.pcd");
  std::ofstream(files[1]) << "VERSION .7\nFIELDS x\n";
  return files;
}

TEST(DecodeAhead, InOrderWithErrorsThenTheEnd) {
  const fs::path dir = fs::temp_directory_path() / ("orthoflow_dec_" + std::to_string(::getpid()));
  const auto files = write_files(dir);
  DecodeAhead decoder(files, false, 2, [&](std::size_t i, DecodeAhead::Slot& slot) {
    read_pcd_into(files[i], slot);
  });
  const std::size_t sizes[] = {1, 0, 2, 3};
  for (int k = 0; k < 4; ++k) {
    DecodeAhead::Slot* slot = decoder.next(std::chrono::milliseconds(5000));
    ASSERT_NE(slot, nullptr) << "file " << k;
    ASSERT_FALSE(slot->end);
    if (k == 1) {
      EXPECT_FALSE(slot->ok);
      EXPECT_NE(slot->error.message.find("bad.pcd"), std::string::npos) << slot->error.message;
    } else {
      ASSERT_TRUE(slot->ok) << slot->error.message;
      EXPECT_EQ(slot->cloud.size(), sizes[k]);
    }
    decoder.release();
  }
  const DecodeAhead::Slot* end = decoder.next(std::chrono::milliseconds(5000));
  ASSERT_NE(end, nullptr);
  EXPECT_TRUE(end->end);
  fs::remove_all(dir);
}

TEST(DecodeAhead, LoopStartsOverAndAHeldSlotIsNotReused) {
  const fs::path dir = fs::temp_directory_path() / ("orthoflow_decl_" + std::to_string(::getpid()));
  auto files = write_files(dir);
  files.erase(files.begin() + 1);  // the good files only: sizes 1, 2, 3
  DecodeAhead decoder(files, true, 1, [&](std::size_t i, DecodeAhead::Slot& slot) {
    read_pcd_into(files[i], slot);
  });
  for (int k = 0; k < 7; ++k) {
    DecodeAhead::Slot* slot = decoder.next(std::chrono::milliseconds(5000));
    ASSERT_NE(slot, nullptr);
    ASSERT_TRUE(slot->ok);
    EXPECT_EQ(slot->cloud.size(), std::size_t(k % 3 + 1));
    // With one slot, nothing more can be decoded while it is held.
    if (k == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      EXPECT_EQ(slot->cloud.size(), 1U);
    }
  }  // next() releases the previous slot itself
  fs::remove_all(dir);
}

}  // namespace
}  // namespace orthoflow::graphs
