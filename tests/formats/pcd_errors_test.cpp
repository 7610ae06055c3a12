// Every IoError code the PCD reader and writer can return, and no crash on any truncation.
#include <gtest/gtest.h>

#include <string>

#include "formats/pcd_io.hpp"
#include "test_clouds.hpp"

namespace ofmt = orthoflow::formats;
using Code = ofmt::IoError::Code;

namespace {

const std::string XYZ_HEADER = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

Code code_of(const std::string& bytes) {
  auto r = ofmt::read_pcd_buffer(bytes, "bad.pcd");
  EXPECT_FALSE(r) << "accepted: " << bytes.substr(0, 120);
  return r ? Code::BAD_HEADER : r.error().code;
}

std::string expect_error(const std::string& bytes, Code expected) {
  auto r = ofmt::read_pcd_buffer(bytes, "bad.pcd");
  if (r) {
    ADD_FAILURE() << "accepted: " << bytes.substr(0, 120);
    return {};
  }
  EXPECT_EQ(r.error().code, expected) << r.error().to_string();
  EXPECT_NE(r.error().message.find("bad.pcd"), std::string::npos) << "message must name the file";
  return r.error().message;
}

TEST(PcdErrors, OpenFailed) {
  auto r = ofmt::read_pcd("/nonexistent/orthoflow/file.pcd");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Code::OPEN_FAILED);
  EXPECT_NE(r.error().message.find("/nonexistent/orthoflow/file.pcd"), std::string::npos);
}

TEST(PcdErrors, WriteFailed) {
  auto r = ofmt::write_pcd(orthoflow::test::make_cloud(2, 1, false, 1), "/nonexistent/dir/out.pcd");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, Code::WRITE_FAILED);
}

TEST(PcdErrors, BadHeaderSaysWhichLine) {
  const std::string msg =
      expect_error(XYZ_HEADER + "WIDTH 1\nFROB 3\nDATA ascii\n1 2 3\n", Code::BAD_HEADER);
  EXPECT_NE(msg.find("line 6"), std::string::npos) << msg;
  expect_error(XYZ_HEADER + "WIDTH 1\nHEIGHT 1\n", Code::BAD_HEADER);  // no DATA
  expect_error("FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n",
               Code::BAD_HEADER);  // no z
  expect_error("FIELDS x y z x\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\nDATA ascii\n1 2 3 4\n",
               Code::BAD_HEADER);
  expect_error("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n",
               Code::BAD_HEADER);
  expect_error(XYZ_HEADER + "WIDTH one\nDATA ascii\n", Code::BAD_HEADER);
  expect_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 1\nDATA ascii\n1 2 3\n",
               Code::BAD_HEADER);
  expect_error(XYZ_HEADER + "HEIGHT 1\nDATA ascii\n1 2 3\n", Code::BAD_HEADER);  // no WIDTH
  expect_error("garbage\x01\x02", Code::BAD_HEADER);
}

TEST(PcdErrors, Unsupported) {
  expect_error("FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nDATA ascii\n1 2 3\n",
               Code::UNSUPPORTED);
  expect_error("FIELDS x y z\nSIZE 4 4 8\nTYPE F F U\nWIDTH 1\nDATA ascii\n1 2 3\n",
               Code::UNSUPPORTED);
  expect_error(XYZ_HEADER + "WIDTH 1\nDATA binary_zstd\n", Code::UNSUPPORTED);
}

TEST(PcdErrors, SizeMismatch) {
  expect_error(XYZ_HEADER + "WIDTH 2\nHEIGHT 2\nPOINTS 5\nDATA ascii\n", Code::SIZE_MISMATCH);
  expect_error(XYZ_HEADER + "WIDTH 1\nDATA ascii\n1 2\n", Code::SIZE_MISMATCH);
  expect_error(XYZ_HEADER + "WIDTH 1\nDATA ascii\n1 2 3 4\n", Code::SIZE_MISMATCH);
  std::string compressed = XYZ_HEADER + "WIDTH 2\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {4, 99};  // 2 points x 12 bytes is 24, not 99
  compressed.append(reinterpret_cast<const char*>(sizes), 8).append("abcd");
  expect_error(compressed, Code::SIZE_MISMATCH);
}

TEST(PcdErrors, TruncatedSaysWhichByteOrLine) {
  std::string binary = XYZ_HEADER + "WIDTH 3\nDATA binary\n";
  binary.append(20, '\0');  // 3 points need 36 bytes
  const std::string msg = expect_error(binary, Code::TRUNCATED);
  EXPECT_NE(msg.find("byte"), std::string::npos) << msg;
  expect_error(XYZ_HEADER + "WIDTH 3\nDATA ascii\n1 2 3\n4 5 6\n", Code::TRUNCATED);
  std::string compressed = XYZ_HEADER + "WIDTH 2\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {400, 24};
  compressed.append(reinterpret_cast<const char*>(sizes), 8).append("abcd");
  expect_error(compressed, Code::TRUNCATED);
  expect_error(XYZ_HEADER + "WIDTH 2\nDATA binary_compressed\n\x01", Code::TRUNCATED);
}

TEST(PcdErrors, CorruptCompressedBlock) {
  std::string compressed = XYZ_HEADER + "WIDTH 2\nDATA binary_compressed\n";
  const std::uint32_t sizes[2] = {6, 24};
  compressed.append(reinterpret_cast<const char*>(sizes), 8).append("\xff\xff\xff\xff\xff\xff", 6);
  expect_error(compressed, Code::CORRUPT_DATA);
  // A block of 4 bytes cannot expand to 1.2 MB: refused before anything is allocated.
  std::string bomb = XYZ_HEADER + "WIDTH 100000\nDATA binary_compressed\n";
  const std::uint32_t bomb_sizes[2] = {4, 1200000};
  bomb.append(reinterpret_cast<const char*>(bomb_sizes), 8).append("abcd");
  expect_error(bomb, Code::CORRUPT_DATA);
}

TEST(PcdErrors, BadNumber) {
  const std::string msg =
      expect_error(XYZ_HEADER + "WIDTH 2\nDATA ascii\n1 2 3\n4 five 6\n", Code::BAD_NUMBER);
  EXPECT_NE(msg.find("line 8"), std::string::npos) << msg;
  expect_error("FIELDS x y z label\nSIZE 4 4 4 1\nTYPE F F F U\nWIDTH 1\nDATA ascii\n1 2 3 256\n",
               Code::BAD_NUMBER);
  expect_error("FIELDS x y z label\nSIZE 4 4 4 4\nTYPE F F F I\nWIDTH 1\nDATA ascii\n1 2 3 nan\n",
               Code::BAD_NUMBER);
}

TEST(PcdErrors, TooLargeIsRefusedBeforeAllocating) {
  expect_error(XYZ_HEADER + "WIDTH 4294967295\nHEIGHT 4294967295\nDATA binary\n", Code::TOO_LARGE);
  expect_error(
      "FIELDS x y z h\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 100000\nWIDTH 1\nDATA binary\n",
      Code::TOO_LARGE);
  // 2^31 declared points in a small file: truncated, and nothing of that size allocated.
  EXPECT_EQ(code_of(XYZ_HEADER + "WIDTH 2147483648\nDATA binary\n"), Code::TRUNCATED);
  EXPECT_EQ(code_of(XYZ_HEADER + "WIDTH 2147483648\nDATA ascii\n1 2 3\n"), Code::TRUNCATED);
}

TEST(PcdErrors, EveryTruncationOfAValidFileIsAnErrorNotACrash) {
  const auto cloud = orthoflow::test::make_cloud(7, 3, true, 9);
  for (auto e : {ofmt::PcdEncoding::ASCII, ofmt::PcdEncoding::BINARY,
                 ofmt::PcdEncoding::BINARY_COMPRESSED}) {
    const std::string whole = ofmt::encode_pcd(cloud, e);
    ASSERT_TRUE(ofmt::read_pcd_buffer(whole));
    // An ASCII file cut inside its very last number is indistinguishable from a file whose last
    // line has no newline: only cuts before that number must fail.
    const std::size_t last =
        (e == ofmt::PcdEncoding::ASCII) ? whole.rfind(' ') + 1 : whole.size() - 1;
    for (std::size_t n = 0; n < last; ++n) {
      auto r = ofmt::read_pcd_buffer(std::string_view(whole).substr(0, n));
      EXPECT_FALSE(r) << ofmt::to_string(e) << " cut at " << n << " of " << whole.size();
    }
  }
}

TEST(PcdErrors, ToStringNamesEveryCode) {
  for (int c = 0; c <= static_cast<int>(Code::TOO_LARGE); ++c) {
    EXPECT_STRNE(ofmt::to_string(static_cast<Code>(c)), "unknown");
  }
}

}  // namespace
