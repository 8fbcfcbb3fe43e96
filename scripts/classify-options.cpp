// scripts/classify-options.cpp — session 17's micro-benchmark (docs/performance.md): the
// classification's lookup two ways on 16 float lanes, over 2^20 random values, 20 passes:
// eight 64-bit gathers of (r, g), (b, σ) at entries i and i + 1 of a 4096-entry table and their
// lerps (what leaf_moments.cpp does), against the transfer function's linear pieces (K compares
// for the piece, then a, b per channel by an in-register permute). Prints ns per voxel.
// Not part of the build (the values are not checked, only timed):
//   g++ -O2 -std=c++20 -march=skylake-avx512 -DHWY_COMPILE_ONLY_STATIC=1 \
//       scripts/classify-options.cpp -o /tmp/classify-options -lhwy && /tmp/classify-options
#include <hwy/highway.h>
#include <chrono>
#include <cstdio>
#include <vector>
#include <random>
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;
__attribute__((noinline, noipa)) float viaGather(const float* vals, size_t n, const double* pairs) {
  D d; hn::RebindToSigned<D> di; hn::Repartition<double, D> dd; hn::RebindToSigned<decltype(dd)> dl; hn::Half<decltype(di)> dih;
  auto acc = hn::Zero(d);
  for (size_t k = 0; k < n; k += hn::Lanes(d)) {
    auto x = hn::Mul(hn::LoadU(d, vals + k), hn::Set(d, 4095.f));
    auto i = hn::Min(hn::ConvertTo(di, x), hn::Set(di, 4094));
    auto t = hn::Sub(x, hn::ConvertTo(d, i));
    auto iLo = hn::PromoteTo(dl, hn::LowerHalf(dih, i)), iHi = hn::PromoteTo(dl, hn::UpperHalf(dih, i));
    auto g = [&](int64_t f, hn::Vec<D>& e, hn::Vec<D>& o) {
      auto lo = hn::BitCast(d, hn::GatherIndex(dd, pairs, hn::Add(hn::ShiftLeft<1>(iLo), hn::Set(dl, f))));
      auto hi = hn::BitCast(d, hn::GatherIndex(dd, pairs, hn::Add(hn::ShiftLeft<1>(iHi), hn::Set(dl, f))));
      e = hn::ConcatEven(d, hi, lo); o = hn::ConcatOdd(d, hi, lo);
    };
    hn::Vec<D> r0,g0,b0,s0,r1,g1,b1,s1;
    g(0,r0,g0); g(1,b0,s0); g(2,r1,g1); g(3,b1,s1);
    auto lerp = [&](auto a, auto b){ return hn::Add(a, hn::Mul(t, hn::Sub(b,a))); };
    auto s = lerp(s0,s1);
    acc = hn::Add(acc, hn::Add(hn::Mul(s, lerp(r0,r1)), hn::Add(hn::Mul(s, lerp(g0,g1)), hn::Mul(s, lerp(b0,b1)))));
  }
  return hn::GetLane(hn::SumOfLanes(d, acc));
}
__attribute__((noinline, noipa)) float viaPermute(const float* vals, size_t n, const float* knots, int K, const float* coef) {
  D d; hn::RebindToSigned<D> di;
  auto acc = hn::Zero(d);
  hn::Vec<D> ca[8];
  for (int c = 0; c < 8; ++c) ca[c] = hn::LoadU(d, coef + 16 * c);
  hn::Vec<D> kn[16]; for (int j = 0; j < K; ++j) kn[j] = hn::Set(d, knots[j]);
  for (size_t k = 0; k < n; k += hn::Lanes(d)) {
    auto x = hn::LoadU(d, vals + k);
    auto seg = hn::Zero(di);
    for (int j = 0; j < K; ++j) seg = hn::Sub(seg, hn::VecFromMask(di, hn::RebindMask(di, hn::Ge(x, kn[j]))));
    auto idx = hn::IndicesFromVec(d, seg);
    auto ev = [&](int c) { return hn::MulAdd(hn::TableLookupLanes(ca[2*c+1], idx), x, hn::TableLookupLanes(ca[2*c], idx)); };
    auto s = ev(0), r = ev(1), g = ev(2), b = ev(3);
    acc = hn::Add(acc, hn::Add(hn::Mul(s, r), hn::Add(hn::Mul(s, g), hn::Mul(s, b))));
  }
  return hn::GetLane(hn::SumOfLanes(d, acc));
}
int main() {
  std::vector<float> v(1 << 20); std::mt19937 rng(1); std::uniform_real_distribution<float> u(0, 1);
  for (auto& x : v) x = u(rng);
  std::vector<double> pairs(4096 * 2); for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = i * 1e-9;
  std::vector<float> knots(16); for (int j = 0; j < 16; ++j) knots[j] = (j + 1) / 17.f;
  std::vector<float> coef(128, 0.5f);
  printf("lanes %zu\n", hn::Lanes(D()));
  for (int rep = 0; rep < 3; ++rep) {
    auto t0 = std::chrono::steady_clock::now(); float a = 0;
    for (int r = 0; r < 20; ++r) a += viaGather(v.data() + r * 16, v.size() - 512, pairs.data());
    auto t1 = std::chrono::steady_clock::now(); float b = 0;
    for (int r = 0; r < 20; ++r) b += viaPermute(v.data() + r * 16, v.size() - 512, knots.data(), 9, coef.data());
    auto t2 = std::chrono::steady_clock::now(); float c = 0;
    for (int r = 0; r < 20; ++r) c += viaPermute(v.data() + r * 16, v.size() - 512, knots.data(), 15, coef.data());
    auto t3 = std::chrono::steady_clock::now();
    auto ns = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count() * 1e9 / (20.0 * double(1 << 20)); };
    printf("gather %.3f ns/voxel  permute K=9 %.3f  K=15 %.3f  (%g %g %g)\n", ns(t0, t1), ns(t1, t2), ns(t2,t3), a, b, c);
  }
}
