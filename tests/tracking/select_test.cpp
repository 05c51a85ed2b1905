#include "tracking/select_impl.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {

using roiflow::tracking::detail::kth_smallest;

// nth_element's answer for rank k of v (v by value: the caller's copy stays as it was).
float reference(std::vector<float> v, std::size_t k) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

TEST(KthSmallest, AgreesWithNthElementAtEveryRankOfRandomValues) {
  std::mt19937 rng(7);
  std::normal_distribution<float> spread(0.f, 3.f);
  for (std::size_t n : {1u, 2u, 3u, 16u, 17u, 33u, 100u, 512u, 1001u}) {
    std::vector<float> v(n);
    for (float& x : v)
      x = spread(rng);
    for (std::size_t k = 0; k < n; k += std::max<std::size_t>(1, n / 37)) {
      std::vector<float> work = v;
      EXPECT_EQ(kth_smallest(work.data(), n, k), reference(v, k)) << "n " << n << " k " << k;
    }
  }
}

TEST(KthSmallest, ManyEqualValuesSortedAndReversedInputs) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> few(0, 3);
  std::vector<float> equal(700), sorted(700), reversed(700);
  for (std::size_t i = 0; i < equal.size(); ++i) {
    equal[i] = static_cast<float>(few(rng));  // only 4 distinct values
    sorted[i] = static_cast<float>(i) * 0.5f;
    reversed[i] = -static_cast<float>(i);
  }
  const std::vector<float> all(700, 1e9f);  // the backward check's "no way back"
  for (const std::vector<float>* v :
       std::vector<const std::vector<float>*>{&equal, &sorted, &reversed, &all}) {
    for (std::size_t k :
         {std::size_t{0}, std::size_t{1}, std::size_t{349}, std::size_t{350}, std::size_t{699}}) {
      std::vector<float> work = *v;
      EXPECT_EQ(kth_smallest(work.data(), work.size(), k), reference(*v, k));
    }
  }
}

TEST(KthSmallest, WithANanItGivesNthElementsAnswer) {
  std::vector<float> v(200);
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = static_cast<float>((i * 37) % 101);
  v[50] = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> work = v;
  const float got = kth_smallest(work.data(), work.size(), 100);
  const float want = reference(v, 100);
  EXPECT_TRUE(got == want || (std::isnan(got) && std::isnan(want)));
}

}  // namespace
