// Memory of GSD writes (issue 13): writing a frame must not allocate a buffer of the file's size.
// This executable replaces the global operator new with one that counts the bytes alive and
// their peak, so the test measures every allocation the writer makes (its own executable: the
// counting allocator must not slow down or perturb the other tests).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <new>

#include "io/gsd_hoomd.hpp"
#include "io/gsd_sample_frame.hpp"
#include "io/gsd_test_util.hpp"

namespace {

std::atomic<std::size_t> g_live{0}, g_peak{0};
constexpr std::size_t kHeader = alignof(std::max_align_t);  // keeps the size in front

void* counted_new(std::size_t n) {
  void* p = std::malloc(n + kHeader);
  if (!p) throw std::bad_alloc();
  *static_cast<std::size_t*>(p) = n;
  const std::size_t live = g_live += n;
  std::size_t peak = g_peak.load();
  while (live > peak && !g_peak.compare_exchange_weak(peak, live)) {
  }
  return static_cast<char*>(p) + kHeader;
}
void counted_delete(void* p) noexcept {
  if (!p) return;
  void* base = static_cast<char*>(p) - kHeader;
  g_live -= *static_cast<std::size_t*>(base);
  std::free(base);
}

// Peak of the bytes alive above those alive when the window opened.
class Window {
 public:
  Window() : base_(g_live.load()) { g_peak = base_; }
  std::size_t extra_peak() const { return g_peak.load() - base_; }

 private:
  std::size_t base_;
};

}  // namespace

void* operator new(std::size_t n) { return counted_new(n); }
void* operator new[](std::size_t n) { return counted_new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t& t) noexcept { return operator new(n, t); }
void operator delete(void* p) noexcept { counted_delete(p); }
void operator delete[](void* p) noexcept { counted_delete(p); }
void operator delete(void* p, std::size_t) noexcept { counted_delete(p); }
void operator delete[](void* p, std::size_t) noexcept { counted_delete(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { counted_delete(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { counted_delete(p); }

namespace hb::gsd {
namespace {

using test::file_bytes;
using test::TempDir;

TEST(GsdStreamingMemory, CountingAllocatorSeesAllocations) {
  Window w;
  { std::vector<char> v(1 << 20); }
  EXPECT_GE(w.extra_peak(), std::size_t{1} << 20);  // the measurement itself is live
}

// An in-memory frame of ~38 MB: the one-shot writer copied every chunk into an encoded plan
// (more than the file size); the streaming writer holds at most its 8 MiB buffer.
TEST(GsdStreamingMemory, AnInMemoryFrameIsWrittenWithoutACopyOfIt) {
  TempDir dir;
  const HoomdFrame f = test::sample_frame(3, 400000, 5);
  Window w;
  write_frame_atomic(dir / "checkpoint.gsd", f);
  const auto size = std::filesystem::file_size(dir / "checkpoint.gsd");
  const std::size_t bound = (std::size_t{8} << 20) + (std::size_t{2} << 20);
  EXPECT_GT(size, 3 * bound);
  EXPECT_LT(w.extra_peak(), bound) << "file " << size << " bytes";
  RecordProperty("extra_peak_bytes", std::to_string(w.extra_peak()));
}

// A frame made row by row through a 16 KiB buffer: byte-identical to the one-shot file, and
// the peak extra memory is a few buffers, ~200 times less than the file.
TEST(GsdStreamingMemory, ASourceFrameNeedsAFewBuffersWhateverItsSize) {
  TempDir dir;
  const std::uint32_t N = 200000;
  const HoomdFrame f = test::sample_frame(3, N, 6);
  write_frame_atomic(dir / "one_shot.gsd", f);
  const auto size = std::filesystem::file_size(dir / "one_shot.gsd");

  FrameSource s = frame_source(f);  // views; rows below are computed, not copied
  s.position = row_source<float>(N, 3, [&f](std::uint64_t i, float* o) {
    for (int k = 0; k < 3; ++k) o[k] = f.position[3 * i + k];
  });
  s.log["particles/hardbody/position_double"] =
      row_source<double>(N, 3, [](std::uint64_t i, double* o) {
        for (int k = 0; k < 3; ++k) o[k] = test::sample_value(6, int(3 * i) + k);
      });
  const std::size_t buffer = 16 << 10;
  Window w;
  write_frame_atomic(dir / "streamed.gsd", s, buffer);
  const std::size_t peak = w.extra_peak();
  EXPECT_LT(peak, 4 * buffer + (32 << 10)) << "file " << size << " bytes";
  RecordProperty("extra_peak_bytes", std::to_string(peak));
  EXPECT_GT(size, 100 * (4 * buffer + (32 << 10)));
  EXPECT_EQ(file_bytes(dir / "streamed.gsd"), file_bytes(dir / "one_shot.gsd"));
}

}  // namespace
}  // namespace hb::gsd
