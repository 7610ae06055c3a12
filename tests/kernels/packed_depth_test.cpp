// Kinect v1 packed 10/11-bit streams (KINECT_V1.md 7.1, 7.2): the scalar twin, the dispatched
// kernel and every compiled SIMD variant against a naive MSB-first bit reader, on the spec's
// composition tables, all-ones frames, random streams of many sizes, pack/unpack round trips, and
// streams that end exactly at a protected page (an over-read faults even without ASan).
#include "kernels/packed_depth.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "kernels/detail/packed_depth_kernel.hpp"

namespace ok = orthoflow::kernels;

namespace {

using Bytes = std::vector<std::uint8_t>;
using Pixels = std::vector<std::uint16_t>;
using UnpackFn = std::function<void(std::span<const std::uint8_t>, std::span<std::uint16_t>)>;

// The oracle: bit i of the stream is bit 7 - i % 8 of byte i / 8; pixel k is bits W*k.. MSB first.
Pixels oracle_unpack(const Bytes& packed, std::size_t n, unsigned bits) {
  Pixels out(n);
  for (std::size_t k = 0; k < n; ++k) {
    unsigned v = 0;
    for (unsigned b = 0; b < bits; ++b) {
      const std::size_t bit = k * bits + b;
      v = (v << 1) | ((packed.at(bit / 8) >> (7 - bit % 8)) & 1U);
    }
    out[k] = static_cast<std::uint16_t>(v);
  }
  return out;
}

struct Variant {
  std::string name;
  UnpackFn run;
};

// Scalar twin, dispatched kernel, and each compiled architecture this CPU supports.
std::vector<Variant> variants(unsigned bits) {
  std::vector<Variant> v;
  if (bits == 11) {
    v.push_back({"scalar", ok::unpack_11bit_scalar});
    v.push_back({"dispatched", ok::unpack_11bit});
  } else {
    v.push_back({"scalar", ok::unpack_10bit_scalar});
    v.push_back({"dispatched", ok::unpack_10bit});
  }
  ok::for_each_available_arch([&](auto arch) {
    UnpackFn fn;
    if (bits == 11) {
      fn = [arch](auto p, auto o) { ok::detail::UnpackKernel<11>{}(arch, p, o); };
    } else {
      fn = [arch](auto p, auto o) { ok::detail::UnpackKernel<10>{}(arch, p, o); };
    }
    v.push_back({decltype(arch)::name(), fn});
  });
  return v;
}

// Exactly packed_bytes(n, bits) random bytes: the vector ends where the stream does (ASan guard).
Bytes random_stream(std::size_t n, unsigned bits, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Bytes b(ok::packed_bytes(n, bits));
  for (auto& x : b) x = static_cast<std::uint8_t>(rng());
  return b;
}

constexpr unsigned WIDTHS[] = {10, 11};

TEST(PackedDepth, PackedBytes) {
  EXPECT_EQ(ok::packed_bytes(0, 11), 0U);
  EXPECT_EQ(ok::packed_bytes(1, 11), 2U);
  EXPECT_EQ(ok::packed_bytes(8, 11), 11U);
  EXPECT_EQ(ok::packed_bytes(9, 11), 13U);
  EXPECT_EQ(ok::packed_bytes(4, 10), 5U);
  EXPECT_EQ(ok::packed_bytes(5, 10), 7U);
  static_assert(ok::packed_bytes(640 * 480, 11) == 422400);
  static_assert(ok::packed_bytes(640 * 480, 10) == 384000);
}

// KINECT_V1.md 7.1: one 11-byte group with distinct bytes, each pixel composed as in the table.
TEST(PackedDepth, Spec11BitCompositionTable) {
  const Bytes b{0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF, 0x10, 0x32, 0x54};
  const Pixels want{
      static_cast<std::uint16_t>(b[0] << 3 | b[1] >> 5),           // b0 | b1[7:5]
      static_cast<std::uint16_t>((b[1] & 0x1F) << 6 | b[2] >> 2),  // b1[4:0] | b2[7:2]
      static_cast<std::uint16_t>((b[2] & 0x3) << 9 | b[3] << 1 |
                                 b[4] >> 7),                       // b2[1:0] | b3 | b4[7]
      static_cast<std::uint16_t>((b[4] & 0x7F) << 4 | b[5] >> 4),  // b4[6:0] | b5[7:4]
      static_cast<std::uint16_t>((b[5] & 0xF) << 7 | b[6] >> 1),   // b5[3:0] | b6[7:1]
      static_cast<std::uint16_t>((b[6] & 0x1) << 10 | b[7] << 2 |
                                 b[8] >> 6),                       // b6[0] | b7 | b8[7:6]
      static_cast<std::uint16_t>((b[8] & 0x3F) << 5 | b[9] >> 3),  // b8[5:0] | b9[7:3]
      static_cast<std::uint16_t>((b[9] & 0x7) << 8 | b[10]),       // b9[2:0] | b10
  };
  EXPECT_EQ(want, (Pixels{0x009, 0x0D1, 0x2CF, 0x09A, 0x5E6, 0x7BC, 0x206, 0x254}));
  EXPECT_EQ(oracle_unpack(b, 8, 11), want);
  // The same group 16 times (so the SIMD blocks see it in every lane), each copy xor-ed with its
  // index so that lanes differ.
  Bytes many;
  Pixels many_want;
  for (std::uint8_t g = 0; g < 16; ++g) {
    for (const std::uint8_t x : b) many.push_back(static_cast<std::uint8_t>(x ^ (g * 0x11)));
  }
  many_want = oracle_unpack(many, 128, 11);
  for (const Variant& v : variants(11)) {
    Pixels got(8, 0xFFFF);
    v.run(b, got);
    EXPECT_EQ(got, want) << v.name;
    Pixels got_many(128, 0xFFFF);
    v.run(many, got_many);
    EXPECT_EQ(got_many, many_want) << v.name;
  }
}

// KINECT_V1.md 7.2: one 5-byte group of the 10-bit stream.
TEST(PackedDepth, Spec10BitCompositionTable) {
  const Bytes b{0xA5, 0x3C, 0x96, 0x0F, 0xE1};
  const Pixels want{
      static_cast<std::uint16_t>(b[0] << 2 | b[1] >> 6),           // b0 | b1[7:6]
      static_cast<std::uint16_t>((b[1] & 0x3F) << 4 | b[2] >> 4),  // b1[5:0] | b2[7:4]
      static_cast<std::uint16_t>((b[2] & 0xF) << 6 | b[3] >> 2),   // b2[3:0] | b3[7:2]
      static_cast<std::uint16_t>((b[3] & 0x3) << 8 | b[4]),        // b3[1:0] | b4
  };
  EXPECT_EQ(want, (Pixels{0x294, 0x3C9, 0x183, 0x3E1}));
  EXPECT_EQ(oracle_unpack(b, 4, 10), want);
  for (const Variant& v : variants(10)) {
    Pixels got(4, 0xFFFF);
    v.run(b, got);
    EXPECT_EQ(got, want) << v.name;
  }
}

TEST(PackedDepth, AllOnesIsAllMaxValues) {
  for (const unsigned bits : WIDTHS) {
    for (const std::size_t n : {std::size_t{1}, std::size_t{37}, std::size_t{640 * 480}}) {
      const Bytes packed(ok::packed_bytes(n, bits), 0xFF);
      const Pixels want(n, static_cast<std::uint16_t>((1U << bits) - 1U));  // 2047 / 1023
      for (const Variant& v : variants(bits)) {
        Pixels got(n, 0);
        v.run(packed, got);
        EXPECT_EQ(got, want) << v.name << " bits " << bits << " n " << n;
      }
    }
  }
}

TEST(PackedDepth, EmptyOutputIsFine) {
  for (const unsigned bits : WIDTHS) {
    for (const Variant& v : variants(bits)) {
      Pixels none;
      v.run({}, none);
      const Bytes some{1, 2, 3};
      v.run(some, none);
    }
  }
  Bytes out{0xAB};
  ok::pack_bits({}, 11, out);
  EXPECT_EQ(out[0], 0xAB);  // nothing written
}

class PackedDepthSizes : public ::testing::TestWithParam<std::size_t> {};

TEST_P(PackedDepthSizes, EveryVariantEqualsTheBitReader) {
  const std::size_t n = GetParam();
  for (const unsigned bits : WIDTHS) {
    const Bytes packed = random_stream(n, bits, static_cast<std::uint32_t>(n * 16 + bits));
    const Pixels want = oracle_unpack(packed, n, bits);
    Pixels scalar(n, 0xFFFF);
    variants(bits).front().run(packed, scalar);
    for (const Variant& v : variants(bits)) {
      Pixels got(n, 0xFFFF);
      v.run(packed, got);
      EXPECT_EQ(got, want) << v.name << " bits " << bits;
      EXPECT_EQ(got, scalar) << v.name << " bits " << bits << " differs from the scalar twin";
    }
  }
}

TEST_P(PackedDepthSizes, PackThenUnpackRoundTrips) {
  const std::size_t n = GetParam();
  for (const unsigned bits : WIDTHS) {
    std::mt19937 rng(static_cast<std::uint32_t>(n * 16 + bits + 1000));
    Pixels values(n);
    for (auto& x : values) x = static_cast<std::uint16_t>(rng());  // upper bits set: masked away
    const std::size_t size = ok::packed_bytes(n, bits);
    Bytes packed(size + 3, 0xEE);
    ok::pack_bits(values, bits, packed);
    EXPECT_EQ(packed[size], 0xEE) << "wrote past packed_bytes";
    if (n * bits % 8 != 0) {
      EXPECT_EQ(packed[size - 1] & ((1U << (8 - n * bits % 8)) - 1U), 0U) << "trailing bits";
    }
    packed.resize(size);
    Pixels masked = values;
    for (auto& x : masked) x = static_cast<std::uint16_t>(x & ((1U << bits) - 1U));
    EXPECT_EQ(oracle_unpack(packed, n, bits), masked) << "bits " << bits;
    for (const Variant& v : variants(bits)) {
      Pixels got(n, 0xFFFF);
      v.run(packed, got);
      EXPECT_EQ(got, masked) << v.name << " bits " << bits;
    }
    // And the other way: random bytes with zero trailing bits survive unpack then pack.
    Bytes stream = random_stream(n, bits, static_cast<std::uint32_t>(n + 77));
    if (n * bits % 8 != 0) stream.back() &= static_cast<std::uint8_t>(0xFF << (8 - n * bits % 8));
    Bytes repacked(size, 0x5A);
    ok::pack_bits(oracle_unpack(stream, n, bits), bits, repacked);
    EXPECT_EQ(repacked, stream) << "bits " << bits;
  }
}

std::vector<std::size_t> sizes() {
  std::vector<std::size_t> s;
  for (std::size_t n = 0; n <= 70; ++n) s.push_back(n);
  for (std::size_t n : {127, 128, 129, 255, 256, 257, 1000, 640 * 480}) s.push_back(n);
  return s;  // 7..9, 15..17, 31..33, 63..65 are inside 0..70
}

INSTANTIATE_TEST_SUITE_P(Sizes, PackedDepthSizes, ::testing::ValuesIn(sizes()));

// The stream ends exactly at a PROT_NONE page: reading one byte past packed_bytes(n, W) faults,
// in any build. Every size up to a few SIMD blocks, so each tail length is tried.
TEST(PackedDepthGuard, NeverReadsPastTheStream) {
  const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  void* map = mmap(nullptr, 2 * page, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(map, MAP_FAILED);
  auto* base = static_cast<std::uint8_t*>(map);
  ASSERT_EQ(mprotect(base + page, page, PROT_NONE), 0);
  std::mt19937 rng(5);
  for (std::size_t i = 0; i < page; ++i) base[i] = static_cast<std::uint8_t>(rng());
  for (const unsigned bits : WIDTHS) {
    for (std::size_t n = 0; n <= 300; ++n) {
      const std::size_t size = ok::packed_bytes(n, bits);
      const std::uint8_t* stream = base + page - size;
      const Bytes copy(stream, stream + size);
      const Pixels want = oracle_unpack(copy, n, bits);
      for (const Variant& v : variants(bits)) {
        Pixels got(n, 0xFFFF);
        v.run({stream, size}, got);
        EXPECT_EQ(got, want) << v.name << " bits " << bits << " n " << n;
      }
    }
  }
  munmap(map, 2 * page);
}

// The exact-size vectors above are what ASan watches; this one states it for a full frame.
TEST(PackedDepthGuard, ExactlySizedFrameVector) {
  constexpr std::size_t N = 640 * 480;
  const Bytes packed = random_stream(N, 11, 9);
  ASSERT_EQ(packed.size(), ok::packed_bytes(N, 11));
  Pixels got(N), want(N);
  ok::unpack_11bit_scalar(packed, want);
  ok::unpack_11bit(packed, got);
  EXPECT_EQ(got, want);
}

#ifndef NDEBUG
TEST(PackedDepthDeathTest, ShortInputIsABug) {
  const Bytes packed(10);
  Pixels out(8);  // needs 11 bytes
  EXPECT_DEATH(ok::unpack_11bit(packed, out), "too short");
  EXPECT_DEATH(ok::unpack_11bit_scalar(packed, out), "too short");
}
#endif

}  // namespace
