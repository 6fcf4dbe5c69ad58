// State keeps each body's hot fields (r, v, q, w, t) in one record and shows them through
// per-field views. These tests pin what the views promise: each reads and writes its own field
// of its own body, and a copied or moved State owns its records (a view never aliases another
// State's storage); a read-only FieldView sees a field in place.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "core/state.hpp"

namespace hb {
namespace {

// Body i's fields, all distinct from one another and from every other body's.
void fill(State& s) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double b = 100.0 * double(i);
    s.r[i] = Vec3(b + 1, b + 2, b + 3);
    s.v[i] = Vec3(b + 4, b + 5, b + 6);
    s.q[i] = Quat(b + 7, b + 8, b + 9, b + 10);
    s.w[i] = Vec3(b + 11, b + 12, b + 13);
    s.t[i] = b + 14;
  }
}

void expect_filled(const State& s, double shift = 0.0) {
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double b = 100.0 * double(i) + shift;
    EXPECT_EQ(s.r[i], Vec3(b + 1, b + 2, b + 3)) << i;
    EXPECT_EQ(s.v[i], Vec3(b + 4, b + 5, b + 6)) << i;
    EXPECT_EQ(s.q[i].coeffs(), Quat(b + 7, b + 8, b + 9, b + 10).coeffs()) << i;
    EXPECT_EQ(s.w[i], Vec3(b + 11, b + 12, b + 13)) << i;
    EXPECT_EQ(s.t[i], b + 14) << i;
  }
}

TEST(State, FieldViewsReadAndWriteTheirOwnFieldOfTheirOwnBody) {
  State s;
  s.resize(5);
  ASSERT_EQ(s.size(), 5u);
  ASSERT_EQ(s.t.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(s.r[i], Vec3::Zero());
    EXPECT_EQ(s.q[i].coeffs(), Quat::Identity().coeffs());
    EXPECT_EQ(s.t[i], 0.0);
  }
  fill(s);
  expect_filled(s);
  // One write changes one field of one body.
  s.v[2] = Vec3(-1, -2, -3);
  EXPECT_EQ(s.v[2], Vec3(-1, -2, -3));
  EXPECT_EQ(s.r[2], Vec3(201, 202, 203));
  EXPECT_EQ(s.w[2], Vec3(211, 212, 213));
  EXPECT_EQ(s.v[1], Vec3(104, 105, 106));
  EXPECT_EQ(s.v[3], Vec3(304, 305, 306));
}

TEST(State, ABodysHotFieldsShareTwoCacheLines) {
  State s;
  s.resize(3);
  const auto* a = reinterpret_cast<const char*>(&s.r[1]);
  const auto addr = [&](const void* p) { return reinterpret_cast<const char*>(p) - a; };
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a) % 64, 0u);
  for (const void* p : {static_cast<const void*>(&s.v[1]), static_cast<const void*>(&s.q[1]),
                        static_cast<const void*>(&s.w[1]), static_cast<const void*>(&s.t[1])}) {
    EXPECT_GE(addr(p), 0);
    EXPECT_LT(addr(p), 128);
  }
  EXPECT_EQ(addr(&s.r[2]), 128);
}

TEST(State, ACopyOwnsItsRecords) {
  State a;
  a.resize(4);
  fill(a);
  State b = a;  // copy construction
  expect_filled(b);
  b.r[1] = Vec3(7, 7, 7);
  b.t[3] = -1.0;
  EXPECT_EQ(a.r[1], Vec3(101, 102, 103));
  EXPECT_EQ(a.t[3], 314.0);
  State c;
  c = a;  // copy assignment
  c.w[0] = Vec3(9, 9, 9);
  EXPECT_EQ(a.w[0], Vec3(11, 12, 13));
  a.v[2] = Vec3(8, 8, 8);
  EXPECT_EQ(c.v[2], Vec3(204, 205, 206));
  EXPECT_EQ(b.v[2], Vec3(204, 205, 206));
}

TEST(State, AMovedStateKeepsItsValuesAndTheSourceItsOwnViews) {
  State a;
  a.resize(3);
  fill(a);
  State b = std::move(a);
  expect_filled(b);
  State c;
  c = std::move(b);
  expect_filled(c);
  // The moved-from States still view their own (reset) storage, not c's.
  a.resize(3);
  a.r[0] = Vec3(5, 5, 5);
  EXPECT_EQ(c.r[0], Vec3(1, 2, 3));
  EXPECT_EQ(a.size(), 3u);
}

TEST(State, AFieldCopiesOutToAVectorAndBackIn) {
  State s;
  s.resize(3);
  fill(s);
  const std::vector<Vec3> r(s.r);
  ASSERT_EQ(r.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(r[i], s.r[i]);
  std::vector<double> t(s.t);
  for (double& x : t) x += 1000.0;
  s.t = t;
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(s.t[i], 100.0 * double(i) + 1014.0);
  EXPECT_EQ(s.r[1], Vec3(101, 102, 103));  // the other fields are untouched
  // A field's view assigned from another State's copies values, it does not re-point.
  State o;
  o.resize(3);
  o.v = s.v;
  o.v[0] = Vec3(0, 0, 1);
  EXPECT_EQ(s.v[0], Vec3(4, 5, 6));
  double sum = 0.0;
  for (double x : s.t) sum += x;
  EXPECT_EQ(sum, 1014.0 + 1114.0 + 1214.0);
}

// The read-only view that observers take sees a State's field in place, with the same values,
// length and order as a copy of it or as a plain vector.
TEST(State, AReadOnlyViewSeesTheFieldInPlace) {
  State s;
  s.resize(4);
  fill(s);
  const FieldView<Vec3> r = s.r;
  const FieldView<Quat> q = s.q;
  const FieldView<double> t = s.t;
  const std::vector<Vec3> copy(s.r);
  const FieldView<Vec3> c = copy;
  ASSERT_EQ(r.size(), 4u);
  ASSERT_EQ(c.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(&r[i], &s.r[i]) << i;  // no copy: the record's own field
    EXPECT_EQ(r[i], c[i]) << i;
    EXPECT_EQ(q[i].coeffs(), s.q[i].coeffs()) << i;
    EXPECT_EQ(t[i], s.t[i]) << i;
  }
  std::size_t k = 0;
  for (const Vec3& x : r) EXPECT_EQ(x, copy[k++]);
  EXPECT_EQ(k, 4u);
  s.r[2] = Vec3(-1, -2, -3);  // a view follows later writes
  EXPECT_EQ(r[2], Vec3(-1, -2, -3));
  State e;
  const FieldView<Vec3> none = e.r;
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.begin(), none.end());
}

}  // namespace
}  // namespace hb
