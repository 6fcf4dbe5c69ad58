// A read-only view of one field of every body, whether the bodies keep it in a vector of its own
// (std::vector<Vec3>) or inside a larger record (State's HotRecord): a base pointer, a stride in
// bytes and a length. The observers and checks that only read positions or orientations take
// this, so they read State's records in place and still accept plain vectors.
//
// A view does not own what it looks at: keep it no longer than the vector or State it came from
// (as a function parameter, it may look at a temporary that lives to the end of the call).
#pragma once
#include <cstddef>
#include <vector>

namespace hb {

template <class T>
class FieldView {
 public:
  FieldView() = default;
  FieldView(const T* first, std::size_t stride_bytes, std::size_t n)
      : p_(reinterpret_cast<const char*>(first)), stride_(stride_bytes), n_(n) {}
  FieldView(const std::vector<T>& v) : FieldView(v.data(), sizeof(T), v.size()) {}  // NOLINT: implicit by design

  const T& operator[](std::size_t i) const { return *reinterpret_cast<const T*>(p_ + i * stride_); }
  std::size_t size() const { return n_; }
  bool empty() const { return n_ == 0; }

  // For range-for: it holds the base pointer and stride itself, so it stays valid when the view
  // it came from (often a temporary) is gone.
  struct Iter {
    const char* p;
    std::size_t stride;
    const T& operator*() const { return *reinterpret_cast<const T*>(p); }
    Iter& operator++() { p += stride; return *this; }
    bool operator==(const Iter& o) const { return p == o.p; }
    bool operator!=(const Iter& o) const { return p != o.p; }
  };
  Iter begin() const { return {p_, stride_}; }
  Iter end() const { return {p_ + n_ * stride_, stride_}; }

 private:
  const char* p_ = nullptr;
  std::size_t stride_ = sizeof(T);
  std::size_t n_ = 0;
};

}  // namespace hb
