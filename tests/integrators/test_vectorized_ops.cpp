// use_vectorized_ops (integrators/sundials/sundials_support.hpp): KINSOL's vector operations on Eigen's loops.
// Element-wise operations must give SUNDIALS' values bit for bit (the Newton update u + p goes through them);
// reductions agree to round-off; clones inherit the table. Each check compares against a plain serial vector,
// so a wrong operation (e.g. a norm without its weights, a linear sum with a and b swapped) fails.
#include "integrators/sundials/sundials_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace shelldyn {
namespace {

struct Pair {  // the same values in a plain serial vector and in one with the vectorized operations
  NVectorPtr plain, fast;
};

Pair make_pair(SunContext& ctx, Index n, std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> U(lo, hi);
  std::vector<double> x(static_cast<size_t>(n));
  for (double& v : x) v = U(rng);
  Pair p{make_serial_vector(n, ctx, x.data()), make_serial_vector(n, ctx, x.data())};
  use_vectorized_ops(p.fast.get());
  return p;
}

void expect_same(N_Vector a, N_Vector b) {
  const Index n = N_VGetLength(a);
  for (Index i = 0; i < n; ++i) ASSERT_EQ(data(a)[i], data(b)[i]) << "entry " << i;
}

TEST(VectorizedOps, ElementwiseBitwiseAndReductionsToRoundOff) {
  SunContext ctx;
  std::mt19937 rng(7);
  for (Index n : {1, 7, 735, 5440}) {
    Pair x = make_pair(ctx, n, rng, -3.0, 3.0), y = make_pair(ctx, n, rng, 0.5, 2.0);
    Pair z = make_pair(ctx, n, rng, 0.0, 1.0);
    for (auto [a, b] : {std::pair{1.0, 1.0}, {1.0, -1.0}, {-1.0, 1.0}, {0.3, -1.7}, {2.0, 1.0}}) {
      N_VLinearSum(a, x.plain.get(), b, y.plain.get(), z.plain.get());
      N_VLinearSum(a, x.fast.get(), b, y.fast.get(), z.fast.get());
      expect_same(z.plain.get(), z.fast.get());
      N_VLinearSum(a, x.plain.get(), b, z.plain.get(), z.plain.get());  // in place (SUNDIALS' axpy branch)
      N_VLinearSum(a, x.fast.get(), b, z.fast.get(), z.fast.get());
      expect_same(z.plain.get(), z.fast.get());
    }
    N_VProd(x.plain.get(), y.plain.get(), z.plain.get());
    N_VProd(x.fast.get(), y.fast.get(), z.fast.get());
    expect_same(z.plain.get(), z.fast.get());
    N_VDiv(x.plain.get(), y.plain.get(), z.plain.get());
    N_VDiv(x.fast.get(), y.fast.get(), z.fast.get());
    expect_same(z.plain.get(), z.fast.get());
    N_VScale(-0.7, x.plain.get(), z.plain.get());
    N_VScale(-0.7, x.fast.get(), z.fast.get());
    expect_same(z.plain.get(), z.fast.get());
    N_VAbs(x.plain.get(), z.plain.get());
    N_VAbs(x.fast.get(), z.fast.get());
    expect_same(z.plain.get(), z.fast.get());
    N_VInv(y.plain.get(), z.plain.get());
    N_VInv(y.fast.get(), z.fast.get());
    expect_same(z.plain.get(), z.fast.get());
    N_VConst(2.5, z.plain.get());
    N_VConst(2.5, z.fast.get());
    expect_same(z.plain.get(), z.fast.get());

    const double tol = 8.0 * std::numeric_limits<double>::epsilon() * std::sqrt(static_cast<double>(n));
    const double w = N_VWL2Norm(x.plain.get(), y.plain.get());
    EXPECT_NEAR(N_VWL2Norm(x.fast.get(), y.fast.get()), w, tol * w);
    const double d = N_VDotProd(x.plain.get(), y.plain.get());
    EXPECT_NEAR(N_VDotProd(x.fast.get(), y.fast.get()), d, tol * N_VWL2Norm(x.plain.get(), y.plain.get()) * std::sqrt(double(n)));
    EXPECT_EQ(N_VMaxNorm(x.fast.get()), N_VMaxNorm(x.plain.get()));
    EXPECT_EQ(N_VMin(x.fast.get()), N_VMin(x.plain.get()));

    NVectorPtr c(N_VClone(x.fast.get()));  // a clone computes with the same table
    EXPECT_EQ(c->ops->nvwl2norm, x.fast->ops->nvwl2norm);
    EXPECT_NE(c->ops->nvwl2norm, x.plain->ops->nvwl2norm);
  }
}

}  // namespace
}  // namespace shelldyn
