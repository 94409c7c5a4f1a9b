#include "dynhet/analysis/s4.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>
#include <fftw3.h>

#include "dynhet/analysis/displacement.hpp"

namespace dynhet::analysis {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using cplx = std::complex<double>;

// Largest |n| of the lattice vectors kept, and the half-plane mode list.
int max_index(const SubboxGrid& g, double q_max) {
  return static_cast<int>(std::floor(q_max * (g.box / g.per_side) / (2 * kPi) + 1e-12));
}

std::vector<std::array<int, 2>> half_plane_modes(const SubboxGrid& g, double q_max) {
  const double dq = 2 * kPi * g.per_side / g.box, q2 = q_max * q_max * (1 + 1e-12);
  const int nm = max_index(g, q_max);
  std::vector<std::array<int, 2>> n;
  for (int ny = 0; ny <= nm; ++ny)
    for (int nx = ny == 0 ? 0 : -nm; nx <= nm; ++nx)
      if ((double(nx) * nx + double(ny) * ny) * dq * dq <= q2) n.push_back({nx, ny});
  return n;
}

// Position relative to the corner of its sub-box, and the sub-box.
struct Local {
  double u, v;
  int box;
};
Local local_position(double x, double y, const SubboxGrid& g) {
  const int r = static_cast<int>(subbox_index(x, y, g)), m = g.per_side;
  const double ell = g.box / m;
  return {x - g.box * std::floor(x / g.box) - (r % m) * ell,
          y - g.box * std::floor(y / g.box) - (r / m) * ell, r};
}

// Smallest 2^a 3^b 5^c 7^d >= n: sizes FFTW does fast.
int fft_size(int n) {
  for (int m = std::max(n, 1);; ++m) {
    int k = m;
    for (int p : {2, 3, 5, 7})
      while (k % p == 0) k /= p;
    if (k == 1) return m;
  }
}

} // namespace

double S4Modes::dq() const { return 2 * kPi * grid.per_side / grid.box; }

// ---- exact sum --------------------------------------------------------------

S4Modes s4_modes_direct(const double* pos0, const double* weight, long n, const SubboxGrid& grid,
                        double q_max) {
  S4Modes out{grid, q_max, half_plane_modes(grid, q_max), {}};
  const int nb = grid.per_side * grid.per_side, nm = max_index(grid, q_max);
  const size_t nmodes = out.n.size();
  out.w.assign(static_cast<size_t>(nb) * nmodes, 0.0);
  // Members of each sub-box with a nonzero weight.
  std::vector<std::vector<long>> members(nb);
  for (long i = 0; i < n; ++i)
    if (weight[i] != 0) members[local_position(pos0[2 * i], pos0[2 * i + 1], grid).box].push_back(i);
  const double dq = out.dq();
  const long chunk = 2048;
  for (int r = 0; r < nb; ++r) {
    // A(nx, ny) = sum_i w_i e^{i dq nx u_i} e^{i dq ny v_i}: phase tables and a matrix product.
    Eigen::MatrixXcd a = Eigen::MatrixXcd::Zero(2 * nm + 1, nm + 1);
    for (size_t c0 = 0; c0 < members[r].size(); c0 += chunk) {
      const long rows = std::min<long>(chunk, static_cast<long>(members[r].size() - c0));
      Eigen::MatrixXcd ex(rows, 2 * nm + 1), ey(rows, nm + 1);
      for (long k = 0; k < rows; ++k) {
        const long i = members[r][c0 + k];
        const Local p = local_position(pos0[2 * i], pos0[2 * i + 1], grid);
        const cplx bx = std::polar(1.0, dq * p.u), by = std::polar(1.0, dq * p.v);
        cplx px = 1.0, py = weight[i];
        for (int l = 0; l <= nm; ++l) {
          ex(k, nm + l) = px, ex(k, nm - l) = std::conj(px), ey(k, l) = py;
          px *= bx, py *= by;
        }
      }
      a.noalias() += ex.transpose() * ey;
    }
    for (size_t k = 0; k < nmodes; ++k)
      out.w[r * nmodes + k] = a(nm + out.n[k][0], out.n[k][1]) / grid.mean_particles; // W_r(q), eq. (16)
  }
  return out;
}

// ---- non-uniform FFT ----------------------------------------------------------

struct S4Grid::Impl {
  SubboxGrid grid;
  double q_max, h, tau, alpha; // alpha = h^2 / (4 tau): the Gaussian in grid units
  int m_points, w, nm;
  std::vector<std::array<int, 2>> modes;
  std::vector<double> deconv;   // per mode: h^2 e^{q^2 tau} / (4 pi tau)
  std::vector<double> kernel_p; // e^{-alpha p^2}, p = -w+1 .. w
  double* in = nullptr;
  fftw_complex* out = nullptr;
  fftw_plan plan = nullptr;

  ~Impl() {
    if (plan) fftw_destroy_plan(plan);
    fftw_free(in);
    fftw_free(out);
  }
  size_t points2() const { return static_cast<size_t>(m_points) * m_points; }
  size_t half2() const { return static_cast<size_t>(m_points) * (m_points / 2 + 1); }
  void spread(const double* pos0, const double* weight, long n);
  void weights_1d(double t, double* k) const;
};

S4Grid::S4Grid(const SubboxGrid& grid, double q_max, S4GridParams p) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.grid = grid, s.q_max = q_max, s.w = p.half_width;
  const double ell = grid.box / grid.per_side;
  s.nm = max_index(grid, q_max);
  const double spacing = p.spacing > 0 ? p.spacing : kPi / (2 * q_max);
  s.m_points = fft_size(static_cast<int>(std::ceil(ell / spacing - 1e-9)));
  if (s.m_points < 2 * s.nm + 1)
    throw std::invalid_argument("S4Grid: grid too coarse for q_max (need h < pi/q_max)");
  s.h = ell / s.m_points;
  // Gaussian width from the error balance: s = tau pi^2/h^2 = w pi R / (2 (2R - 1)).
  const double r = kPi / (s.h * q_max), sv = s.w * kPi * r / (2 * (2 * r - 1));
  s.tau = sv * s.h * s.h / (kPi * kPi);
  s.alpha = s.h * s.h / (4 * s.tau);
  for (int q = -s.w + 1; q <= s.w; ++q) s.kernel_p.push_back(std::exp(-s.alpha * q * q));
  s.modes = half_plane_modes(grid, q_max);
  const double dq = 2 * kPi / ell;
  for (const auto& k : s.modes) {
    const double q2 = dq * dq * (double(k[0]) * k[0] + double(k[1]) * k[1]);
    s.deconv.push_back(s.h * s.h * std::exp(q2 * s.tau) / (4 * kPi * s.tau));
  }
  const int nb = grid.per_side * grid.per_side;
  s.in = fftw_alloc_real(nb * s.points2());
  s.out = fftw_alloc_complex(nb * s.half2());
  const int dims[2] = {s.m_points, s.m_points};
  s.plan = fftw_plan_many_dft_r2c(2, dims, nb, s.in, nullptr, 1, static_cast<int>(s.points2()), s.out,
                                  nullptr, 1, static_cast<int>(s.half2()),
                                  p.measure_plan ? FFTW_MEASURE : FFTW_ESTIMATE);
  if (!s.plan) throw std::runtime_error("S4Grid: FFTW could not plan the transform");
}

S4Grid::~S4Grid() = default;
int S4Grid::points() const { return impl_->m_points; }
double S4Grid::spacing() const { return impl_->h; }
double S4Grid::oversampling() const { return kPi / (impl_->h * impl_->q_max); }
double S4Grid::error_bound() const {
  const double r = oversampling();
  return std::exp(-kPi * impl_->w * (r - 1) / (r - 0.5));
}

// Gaussian weights at the 2w grid points p = -w+1 .. w around a particle at
// fractional offset t in [0, 1) from its grid point, by fast Gaussian
// gridding: e^{-alpha (t-p)^2} = e^{-alpha t^2} (e^{2 alpha t})^p e^{-alpha p^2},
// two exponentials per particle and dimension.
void S4Grid::Impl::weights_1d(double t, double* k) const {
  const double e1 = std::exp(-alpha * t * t), e2 = std::exp(2 * alpha * t), inv_e2 = 1 / e2;
  double pw = e1;
  for (int p = w - 1; p < 2 * w; ++p) k[p] = pw * kernel_p[p], pw *= e2; // p' = 0 .. w
  pw = e1 * inv_e2;
  for (int p = w - 2; p >= 0; --p) k[p] = pw * kernel_p[p], pw *= inv_e2; // p' = -1 .. -w+1
}

void S4Grid::Impl::spread(const double* pos0, const double* weight, long n) {
  std::fill(in, in + grid.per_side * grid.per_side * points2(), 0.0);
  const int m = m_points, span = 2 * w;
  std::vector<double> kx(span), ky(span);
  std::vector<int> ix(span), iy(span);
  for (long i = 0; i < n; ++i) {
    if (weight[i] == 0) continue;
    const Local p = local_position(pos0[2 * i], pos0[2 * i + 1], grid);
    const double gx = p.u / h, gy = p.v / h;
    const int lx = static_cast<int>(gx), ly = static_cast<int>(gy); // u, v >= 0
    weights_1d(gx - lx, kx.data());
    weights_1d(gy - ly, ky.data());
    for (int q = 0; q < span; ++q) kx[q] *= weight[i];
    double* g = in + p.box * points2();
    const int y0 = ly - w + 1;
    for (int a = 0; a < span; ++a) ix[a] = ((lx - w + 1 + a) % m + m) % m; // periodic on the sub-box
    if (y0 >= 0 && y0 + span <= m) { // the window does not wrap in y: contiguous
      for (int a = 0; a < span; ++a) {
        double* row = g + static_cast<size_t>(ix[a]) * m + y0;
        for (int b = 0; b < span; ++b) row[b] += kx[a] * ky[b];
      }
    } else {
      for (int b = 0; b < span; ++b) iy[b] = ((y0 + b) % m + m) % m;
      for (int a = 0; a < span; ++a) {
        double* row = g + static_cast<size_t>(ix[a]) * m;
        for (int b = 0; b < span; ++b) row[iy[b]] += kx[a] * ky[b];
      }
    }
  }
}

S4Modes S4Grid::modes(const double* pos0, const double* weight, long n) {
  Impl& s = *impl_;
  s.spread(pos0, weight, n);
  fftw_execute(s.plan);
  S4Modes out{s.grid, s.q_max, s.modes, {}};
  const int nb = s.grid.per_side * s.grid.per_side, m = s.m_points, half = m / 2 + 1;
  const size_t nmodes = s.modes.size();
  out.w.resize(nb * nmodes);
  for (int r = 0; r < nb; ++r) {
    const fftw_complex* f = s.out + r * s.half2();
    for (size_t k = 0; k < nmodes; ++k) {
      const int kx = (s.modes[k][0] + m) % m, ky = s.modes[k][1];
      const fftw_complex& v = f[static_cast<size_t>(kx) * half + ky];
      // FFTW's forward sign is e^{-iq.r}: W_r(q) is the conjugate, deconvolved, over N.
      out.w[r * nmodes + k] = cplx(v[0], -v[1]) * (s.deconv[k] / s.grid.mean_particles);
    }
  }
  return out;
}

// ---- shells -------------------------------------------------------------------

S4Shells s4_shells(const S4Modes& m) {
  const int nb = m.grid.per_side * m.grid.per_side;
  const size_t nmodes = m.n.size();
  const double dq = m.dq(), big_n = m.grid.mean_particles;
  S4Shells out;
  std::vector<double> sum_v, sum_q;
  std::vector<int> count;
  for (size_t k = 0; k < nmodes; ++k) {
    double s2 = 0;
    cplx s1 = 0;
    for (int r = 0; r < nb; ++r) {
      const cplx w = m.w[r * nmodes + k];
      s1 += w, s2 += std::norm(w);
    }
    const bool zero = m.n[k][0] == 0 && m.n[k][1] == 0;
    // N [<W_r(q) W_r(-q)> - <W_r(q)><W_r(-q)>], eq. (15); whole box: N |W(q)|^2.
    const double v = nb > 1 ? big_n * (s2 / nb - std::norm(s1 / double(nb))) : (zero ? kNaN : big_n * s2);
    const double nn = std::hypot(double(m.n[k][0]), double(m.n[k][1]));
    const size_t shell = static_cast<size_t>(std::lround(nn));
    if (shell >= count.size())
      sum_v.resize(shell + 1, 0.0), sum_q.resize(shell + 1, 0.0), count.resize(shell + 1, 0);
    sum_v[shell] += v, sum_q[shell] += nn * dq, ++count[shell];
  }
  for (size_t s = 0; s < count.size(); ++s) {
    if (count[s] == 0) continue;
    // Each half-plane mode stands for q and -q, which have the same value.
    out.q.push_back(sum_q[s] / count[s]);
    out.s4.push_back(sum_v[s] / count[s]);
    out.n_vectors.push_back(s == 0 ? 1 : 2 * count[s]);
  }
  return out;
}

} // namespace dynhet::analysis
