// S4(q,t), eqs. (15)-(16): the direct sum against the definition, the FFT
// grid against the direct sum within its error bound, S4(0) = chi4, and the
// OZ fits recovering xi from a field of known correlation length.
#include <cmath>
#include <complex>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "dynhet/analysis/displacement.hpp"
#include "dynhet/analysis/fits.hpp"
#include "dynhet/analysis/s4.hpp"

using namespace dynhet::analysis;
using cplx = std::complex<double>;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Field {
  long n;
  double box;
  std::vector<double> pos, w;
};

// Random unwrapped positions with 0/1 weights (slow with probability p).
Field random_field(long n, double box, double p, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  Field f{n, box, std::vector<double>(2 * n), std::vector<double>(n)};
  for (long i = 0; i < 2 * n; ++i) f.pos[i] = box * u(gen) + box * std::floor(3 * u(gen) - 1);
  for (long i = 0; i < n; ++i) f.w[i] = u(gen) < p ? 1.0 : 0.0;
  return f;
}

double abs_sum(const std::vector<double>& w) {
  double s = 0;
  for (double v : w) s += std::abs(v);
  return s;
}

// Largest |W_grid - W_direct| over all sub-boxes and modes.
double max_mode_error(const S4Modes& a, const S4Modes& b) {
  double e = 0;
  for (size_t k = 0; k < a.w.size(); ++k) e = std::max(e, std::abs(a.w[k] - b.w[k]));
  return e;
}

} // namespace

TEST(S4, DirectSumIsTheDefinition) {
  const Field f = random_field(300, 20.0, 0.5, 1);
  const SubboxGrid grid = make_subbox_grid(f.n, f.box, 75); // 2 x 2 sub-boxes of side 10
  ASSERT_EQ(grid.per_side, 2);
  const S4Modes m = s4_modes_direct(f.pos.data(), f.w.data(), f.n, grid, 2.5);
  const double dq = 2 * kPi / 10.0;
  ASSERT_EQ(m.n.size(), 23u); // half plane of |n| <= 3.98: ny = 0, 1, 2, 3 hold 4, 7, 7, 5
  for (size_t k = 0; k < m.n.size(); ++k)
    for (int r = 0; r < 4; ++r) {
      // eq. (16) term by term, with the unwrapped positions as they are.
      cplx s = 0;
      for (long i = 0; i < f.n; ++i) {
        const double x = std::fmod(std::fmod(f.pos[2 * i], f.box) + f.box, f.box);
        const double y = std::fmod(std::fmod(f.pos[2 * i + 1], f.box) + f.box, f.box);
        if (int(y / 10.0) * 2 + int(x / 10.0) != r) continue;
        s += f.w[i] * std::polar(1.0, dq * (m.n[k][0] * f.pos[2 * i] + m.n[k][1] * f.pos[2 * i + 1]));
      }
      EXPECT_NEAR(std::abs(m.w[r * m.n.size() + k] - s / grid.mean_particles), 0.0, 1e-12);
    }
}

TEST(S4, GridMatchesDirectSumWithinItsErrorBound) {
  const Field f = random_field(4000, 80.0, 0.4, 2);
  const double l1 = abs_sum(f.w);
  for (int target : {4000, 450}) { // whole box, and 3 x 3 sub-boxes
    const SubboxGrid grid = make_subbox_grid(f.n, f.box, target);
    const S4Modes exact = s4_modes_direct(f.pos.data(), f.w.data(), f.n, grid, 1.0);
    const S4Shells se = s4_shells(exact);
    // Default (oversampling 2, half-width 4) and a coarse grid (R = 1.3, half-width 3).
    const S4GridParams coarse{kPi / 1.3, 3};
    const S4GridParams params[2] = {S4GridParams{}, coarse};
    for (int k = 0; k < 2; ++k) {
      S4Grid g(grid, 1.0, params[k]);
      const S4Modes approx = g.modes(f.pos.data(), f.w.data(), f.n);
      ASSERT_EQ(approx.n, exact.n);
      // The bound is on |sum_i w_i e^{iq.r_i}|, i.e. on N |W_r|.
      EXPECT_LT(max_mode_error(approx, exact) * grid.mean_particles, g.error_bound() * l1)
          << "m=" << grid.per_side << " R=" << g.oversampling();
      if (k == 0) { // the default meets the target of 1% on S4 for q <= 1
        const S4Shells sa = s4_shells(approx);
        for (size_t s = 0; s < se.q.size(); ++s)
          if (std::isfinite(se.s4[s])) {
            EXPECT_NEAR(sa.s4[s], se.s4[s], 0.01 * se.s4[s]);
          }
      }
    }
  }
}

TEST(S4, ZeroWaveVectorShellIsChi4) {
  // W_r(0) = Q_r, so S4(0) = N[<Q_r^2> - <Q_r>^2]: the displacement kernel's chi4.
  std::mt19937_64 gen(9);
  std::normal_distribution<double> g(0, 0.6);
  Field f = random_field(3000, 60.0, 0.0, 3);
  std::vector<double> pt(2 * f.n);
  for (long i = 0; i < 2 * f.n; ++i) pt[i] = f.pos[i] + g(gen);
  DisplacementSpec spec;
  spec.grids = {make_subbox_grid(f.n, f.box, 190)}; // 4 x 4
  spec.cutoffs = {0.6};
  const OriginIndex origin(f.pos.data(), f.n, spec);
  DisplacementResult r;
  std::vector<double> d2(f.n);
  const std::vector<std::uint8_t> species(f.n, 0);
  displacement_pass(f.pos.data(), pt.data(), species.data(), f.n, origin, spec, r, d2.data());
  overlap_weights(d2.data(), f.n, 0.6, f.w);
  const S4Shells direct = s4_shells(s4_modes_direct(f.pos.data(), f.w.data(), f.n, spec.grids[0], 1.0));
  EXPECT_DOUBLE_EQ(direct.q[0], 0.0);
  EXPECT_NEAR(direct.s4[0], r.chi4[0], 1e-12 * r.chi4[0]);
  S4Grid grid(spec.grids[0], 1.0);
  const S4Shells fft = s4_shells(grid.modes(f.pos.data(), f.w.data(), f.n));
  EXPECT_NEAR(fft.s4[0], r.chi4[0], 1e-3 * r.chi4[0]); // grid error ~1e-4 of sum |w| at most
}

namespace {

// A field on the sites of a square lattice (spacing 1, side L) whose
// whole-box S4 is exactly p(|q|) at every wave vector with |q| <= q_cut:
// w_j = N^-1/2 sum_q c_q e^{-iq.r_j}, |c_q|^2 = p(|q|), random phases,
// c_{-q} = conj c_q (real w). Lattice sums make N |W(q)|^2 = |c_q|^2.
Field lattice_field(int side, double q_cut, const std::function<double(double)>& p, unsigned seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> u(0, 2 * kPi);
  const long n = long(side) * side;
  const double dq = 2 * kPi / side;
  const int nm = static_cast<int>(q_cut / dq);
  // c(nx, ny) on the half plane (ny > 0, or ny = 0 and nx > 0); zero elsewhere.
  std::vector<cplx> c((2 * nm + 1) * (nm + 1), 0.0);
  for (int ny = 0; ny <= nm; ++ny)
    for (int nx = -nm; nx <= nm; ++nx) {
      const double q = dq * std::hypot(nx, ny);
      if ((ny == 0 && nx <= 0) || q > q_cut) continue;
      c[(nx + nm) * (nm + 1) + ny] = std::polar(std::sqrt(p(q)), u(gen));
    }
  Field f{n, double(side), std::vector<double>(2 * n), std::vector<double>(n)};
  // Separable sum: b(nx, y) = sum_ny c e^{-i dq ny y}, then over nx.
  std::vector<cplx> b((2 * nm + 1) * side);
  for (int y = 0; y < side; ++y)
    for (int nx = -nm; nx <= nm; ++nx) {
      cplx s = 0;
      for (int ny = 0; ny <= nm; ++ny)
        s += c[(nx + nm) * (nm + 1) + ny] * std::polar(1.0, -dq * ny * (y + 0.5));
      b[(nx + nm) * side + y] = s;
    }
  for (int x = 0; x < side; ++x)
    for (int y = 0; y < side; ++y) {
      cplx s = 0;
      for (int nx = -nm; nx <= nm; ++nx) s += std::polar(1.0, -dq * nx * (x + 0.5)) * b[(nx + nm) * side + y];
      const long i = long(x) * side + y;
      f.pos[2 * i] = x + 0.5, f.pos[2 * i + 1] = y + 0.5;
      f.w[i] = 2 * s.real() / std::sqrt(double(n)); // q and -q together
    }
  return f;
}

// The exact shell averages of p over the lattice vectors, as s4_shells forms them.
std::vector<double> shell_means(const S4Modes& m, const std::function<double(double)>& p) {
  std::vector<double> sum, cnt;
  for (const auto& k : m.n) {
    const double nn = std::hypot(k[0], k[1]);
    const size_t s = std::lround(nn);
    if (s >= sum.size()) sum.resize(s + 1, 0.0), cnt.resize(s + 1, 0.0);
    sum[s] += (s == 0 ? NAN : p(nn * m.dq())), ++cnt[s];
  }
  for (size_t s = 0; s < sum.size(); ++s) sum[s] /= cnt[s];
  return sum;
}

} // namespace

TEST(S4, OzFitRecoversTheCorrelationLengthOfASyntheticField) {
  const double chi0 = 40.0, xi = 4.0;
  auto oz = [&](double q) { return chi0 / (1 + q * q * xi * xi); };
  const Field f = lattice_field(256, 1.0, oz, 4);
  const SubboxGrid whole = make_subbox_grid(f.n, f.box, static_cast<int>(f.n));
  S4Grid grid(whole, 1.0);
  const S4Modes m = grid.modes(f.pos.data(), f.w.data(), f.n);
  // Every mode: |sum_i w_i e^{iq.r_i}| = sqrt(N p(|q|)), to the grid's error
  // estimate delta = error_bound * sum_i |w_i|.
  const double big_n = whole.mean_particles, delta = grid.error_bound() * abs_sum(f.w);
  for (size_t k = 1; k < m.n.size(); ++k) {
    const double p = oz(m.dq() * std::hypot(m.n[k][0], m.n[k][1]));
    EXPECT_NEAR(big_n * std::abs(m.w[k]), std::sqrt(big_n * p), delta);
  }
  // Shells: means of p over their vectors, each within (2 delta sqrt(N p) + delta^2)/N.
  const S4Shells sh = s4_shells(m);
  const std::vector<double> expect = shell_means(m, oz);
  for (size_t s = 1; s < sh.q.size(); ++s)
    EXPECT_NEAR(sh.s4[s], expect[s], (2 * delta * std::sqrt(big_n * expect[s]) + delta * delta) / big_n);
  // Shell averaging over |q| within +-dq/2 biases S4 by about (xi dq)^2 / 12
  // relative = 0.8e-3 here: xi and chi0 come back within 1%.
  const OzFit fit = fit_oz(sh.q, sh.s4);
  EXPECT_TRUE(fit.range_ok);
  EXPECT_NEAR(fit.xi, xi, 0.01 * xi);
  EXPECT_NEAR(fit.chi0, chi0, 0.01 * chi0);
  EXPECT_LE(fit.q_fit_max * fit.xi, 1.0);
}

TEST(S4, OzWithQuarticTermRecoversA) {
  const double chi0 = 25.0, xi = 5.0, a = 0.5;
  auto form = [&](double q) {
    const double x2 = q * q * xi * xi;
    return chi0 / (1 + x2 + a * a * x2 * x2);
  };
  const Field f = lattice_field(256, 1.0, form, 5);
  const SubboxGrid whole = make_subbox_grid(f.n, f.box, static_cast<int>(f.n));
  S4Grid grid(whole, 1.0);
  const S4Shells sh = s4_shells(grid.modes(f.pos.data(), f.w.data(), f.n));
  const OzFit fit = fit_oz_a2(sh.q, sh.s4);
  // Same shell-averaging bias as above, (xi dq)^2/12 ~ 1.3e-3: 2% on xi and A.
  EXPECT_NEAR(fit.xi, xi, 0.02 * xi);
  EXPECT_NEAR(fit.a, a, 0.02 * a + 0.01);
  EXPECT_NEAR(fit.chi0, chi0, 0.01 * chi0);
}
