// Seam stitching (stitch_seams.hpp): the Gauss-Legendre points of the seams, the least-squares
// systems (scalar, HL2) and their solves, as the chain stitch_points -> unknown_texels ->
// assemble (design_matrix, normal_matrix) -> factorise; per image: initial_values -> solve ->
// write back.
#include "stitch_seams.hpp"


#include "hemilight/error.hpp"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hemilight::bake_detail {

namespace {

// Parameters in [0, 1] where side s's bilinear coordinates (texel coordinates - 0.5) cross an
// integer, appended to `cuts`.
void grid_crossings(const seam_side& s, std::vector<double>& cuts) {
  for (int axis = 0; axis < 2; ++axis) {
    const double a = double(s.t0[axis]) - 0.5, b = double(s.t1[axis]) - 0.5;
    if (a == b) continue;
    const double lo = std::min(a, b), hi = std::max(a, b);
    for (double k = std::ceil(lo); k <= hi; ++k) {
      const double t = (k - a) / (b - a);
      if (t > 0.0 && t < 1.0) cuts.push_back(t);
    }
  }
}

}  // namespace

std::vector<stitch_point> stitch_points(const std::vector<seam_piece>& pieces, const std::vector<page_rect>& pages,
                                        std::size_t grid_width) {
  // Three-point Gauss-Legendre on [-1, 1]: exact for the squared step, a polynomial of degree 4
  // along a part where both sides stay in one bilinear cell.
  const double node[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, weight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  std::vector<stitch_point> out;
  std::vector<double> cuts;
  for (const seam_piece& p : pieces) {
    if (!p.coplanar || p.walled) continue;
    cuts.assign({0.0, 1.0});
    grid_crossings(p.a, cuts);
    grid_crossings(p.b, cuts);
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
      const double h = 0.5 * (cuts[i + 1] - cuts[i]), m = 0.5 * (cuts[i + 1] + cuts[i]);
      if (!(h > 1e-9)) continue;
      for (int g = 0; g < 3; ++g) {
        const auto t = float(m + h * node[g]);
        stitch_point s;
        const page_rect &ra = pages[std::size_t(p.a.page)], &rb = pages[std::size_t(p.b.page)];
        const glm::vec2 ta = p.a.t0 + t * (p.a.t1 - p.a.t0), tb = p.b.t0 + t * (p.b.t1 - p.b.t0);
        s.a = bilinear_footprint(ra, grid_width, ta);
        s.b = bilinear_footprint(rb, grid_width, tb);
        for (std::size_t k = 0; k < 2; ++k) {
          s.a_in[k] = bilinear_footprint(ra, grid_width, ta + float(k + 1) * p.a.inward);
          s.b_in[k] = bilinear_footprint(rb, grid_width, tb + float(k + 1) * p.b.inward);
        }
        s.weight = weight[g] * h * double(p.length_texels);
        s.ta = p.a.tangent;
        s.ba = p.a.bitangent;
        s.tb = p.b.tangent;
        s.bb = p.b.bitangent;
        out.push_back(s);
      }
    }
  }
  return out;
}

struct seam_stitcher::system {
  int components = 1;  // unknowns per texel: 1 (scalar images), 3 (the HL2 triple)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
};

namespace {

using triplet = Eigen::Triplet<double>;

std::vector<std::size_t> unknown_texels(const std::vector<stitch_point>& points) {
  std::vector<std::size_t> t;
  t.reserve(8 * points.size());
  for (const stitch_point& p : points)
    for (std::size_t k = 0; k < 4; ++k) {
      t.push_back(p.a.texel[k]);
      t.push_back(p.b.texel[k]);
    }
  std::sort(t.begin(), t.end());
  t.erase(std::unique(t.begin(), t.end()), t.end());
  return t;
}

Eigen::Index column_of(const std::vector<std::size_t>& texels, std::size_t texel) {
  return Eigen::Index(std::lower_bound(texels.begin(), texels.end(), texel) - texels.begin());
}

// The HL2 basis directions' azimuths in the tangent frame (docs/bake.md): (-1/sqrt6, 1/sqrt2) is
// at 120 degrees, (-1/sqrt6, -1/sqrt2) at 240, (sqrt(2/3), 0) at 0.
constexpr double hl2_azimuth[3] = {2.0943951023931957, 4.1887902047863905, 0.0};

// Row r of the map from a side's HL2 triple to (mean, first harmonic . e1, first harmonic . e2)
// with (e1, e2) = side a's (tangent, bitangent): the triple samples h(phi) = c0 + c1 . (cos phi,
// sin phi) at the three azimuths, so c0 = mean, c1 = 2/3 sum h_k (cos, sin)(phi_k), and the
// world-space harmonic is c1.x t + c1.y b.
double hl2_coefficient(int r, int k, const glm::vec3& t, const glm::vec3& b, const glm::vec3& e1, const glm::vec3& e2) {
  if (r == 0) return 1.0 / 3.0;
  const glm::vec3& e = r == 1 ? e1 : e2;
  const double c = std::cos(hl2_azimuth[k]), s = std::sin(hl2_azimuth[k]);
  return 2.0 / 3.0 * (c * double(glm::dot(t, e)) + s * double(glm::dot(b, e)));
}

// A = W^(1/2) times the map from the unknowns to the steps at the points.
Eigen::SparseMatrix<double> design_matrix(const std::vector<stitch_point>& points, const std::vector<std::size_t>& texels,
                                          int components) {
  std::vector<triplet> entries;
  entries.reserve(points.size() * std::size_t(8 * components * components));
  const auto n = Eigen::Index(components);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const stitch_point& p = points[i];
    const double w = std::sqrt(p.weight);
    for (std::size_t k = 0; k < 4; ++k) {
      const Eigen::Index ca = column_of(texels, p.a.texel[k]), cb = column_of(texels, p.b.texel[k]);
      for (int r = 0; r < components; ++r) {
        const Eigen::Index row = Eigen::Index(i) * n + r;
        for (int c = 0; c < components; ++c) {
          const double alpha_a = components == 1 ? 1.0 : hl2_coefficient(r, c, p.ta, p.ba, p.ta, p.ba);
          const double alpha_b = components == 1 ? 1.0 : hl2_coefficient(r, c, p.tb, p.bb, p.ta, p.ba);
          entries.emplace_back(row, ca * n + c, w * double(p.a.weight[k]) * alpha_a);
          entries.emplace_back(row, cb * n + c, -w * double(p.b.weight[k]) * alpha_b);
        }
      }
    }
  }
  Eigen::SparseMatrix<double> a(Eigen::Index(points.size()) * n, Eigen::Index(texels.size()) * n);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

// A^T A + lambda I.
Eigen::SparseMatrix<double> normal_matrix(const Eigen::SparseMatrix<double>& a) {
  Eigen::SparseMatrix<double> n = a.transpose() * a;
  Eigen::SparseMatrix<double> id(n.rows(), n.cols());
  id.setIdentity();
  return n + stitch_regularization * id;
}

void factorise(Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>& ldlt, const Eigen::SparseMatrix<double>& n) {
  ldlt.compute(n);
  // The matrix is symmetric positive definite by construction (lambda > 0): a failure is a bug.
  if (ldlt.info() != Eigen::Success) throw error(status::internal, "bake: the seam stitching system could not be factorised");
}

// The values to start from at the unknown texels, channel c of texel k at start[k * ch + c] for
// k in `texels`: the image's own where filled, else the mean of the filled, unblocked texels in
// the smallest square ring around it (up to 4 rings, within its page's grid rows and columns) that
// holds one, else 0. Local: O(unknowns), not O(image).
std::vector<float> initial_values(const image& img, const std::vector<std::uint8_t>& filled, const std::uint8_t* blocked,
                                  const std::vector<std::size_t>& texels) {
  const auto ch = std::size_t(img.channels);
  const auto w = std::ptrdiff_t(img.width), h = std::ptrdiff_t(img.height);
  std::vector<float> start(texels.size() * ch, 0.0f);
  for (std::size_t u = 0; u < texels.size(); ++u) {
    const std::size_t k = texels[u];
    if (filled[k]) {
      for (std::size_t c = 0; c < ch; ++c) start[u * ch + c] = img.pixels[k * ch + c];
      continue;
    }
    const auto x = std::ptrdiff_t(k % std::size_t(w)), y = std::ptrdiff_t(k / std::size_t(w));
    for (std::ptrdiff_t ring = 1; ring <= 4; ++ring) {
      double sum[4] = {0.0, 0.0, 0.0, 0.0};
      std::size_t n = 0;
      for (std::ptrdiff_t dy = -ring; dy <= ring; ++dy)
        for (std::ptrdiff_t dx = -ring; dx <= ring; ++dx) {
          const std::ptrdiff_t xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const auto q = std::size_t(yy * w + xx);
          if (!filled[q] || (blocked && blocked[q])) continue;
          for (std::size_t c = 0; c < ch; ++c) sum[c] += double(img.pixels[q * ch + c]);
          ++n;
        }
      if (n == 0) continue;
      for (std::size_t c = 0; c < ch; ++c) start[u * ch + c] = float(sum[c] / double(n));
      break;
    }
  }
  return start;
}

// The points whose irradiance step the two sides' gradients explain (stitch_seams.hpp, top): the
// others sit on a discontinuity.
std::vector<stitch_point> continuous_points(std::vector<stitch_point> points, const std::vector<std::size_t>& texels,
                                           const std::vector<float>& start) {
  const auto lookup = [&](const footprint& f) {
    return bilinear_luminance(f, [&](std::size_t k) { return start.data() + 3 * std::size_t(column_of(texels, k)); });
  };
  std::vector<stitch_point> kept;
  kept.reserve(points.size());
  for (const stitch_point& p : points) {
    const double ya = lookup(p.a), yb = lookup(p.b);
    const double ga = std::fabs(lookup(p.a_in[0]) - lookup(p.a_in[1])), gb = std::fabs(lookup(p.b_in[0]) - lookup(p.b_in[1]));
    if (std::fabs(ya - yb) <= 3.0 * (ga + gb) + 0.05 * (std::fabs(ya) + std::fabs(yb))) kept.push_back(p);
  }
  return kept;
}

}  // namespace

seam_stitcher::seam_stitcher(const std::vector<seam_piece>& pieces, const std::vector<page_rect>& pages, int grid_width, bool hl2,
                             const image& irradiance, const std::vector<std::uint8_t>& filled, const std::uint8_t* blocked) {
  std::vector<stitch_point> all = stitch_points(pieces, pages, std::size_t(grid_width));
  if (all.empty()) return;
  // The irradiance at every texel the points read (their inward lookups too).
  std::vector<std::size_t> read;
  for (const stitch_point& p : all)
    for (const footprint* f : {&p.a, &p.b, &p.a_in[0], &p.a_in[1], &p.b_in[0], &p.b_in[1]}) read.insert(read.end(), f->texel.begin(), f->texel.end());
  std::sort(read.begin(), read.end());
  read.erase(std::unique(read.begin(), read.end()), read.end());
  const std::vector<float> start = initial_values(irradiance, filled, blocked, read);
  const std::size_t count = all.size();
  points_ = continuous_points(std::move(all), read, start);
  discontinuities_ = count - points_.size();
  texels_ = unknown_texels(points_);
  if (texels_.empty()) return;
  scalar_ = std::make_unique<system>();
  factorise(scalar_->ldlt, normal_matrix(design_matrix(points_, texels_, 1)));
  if (hl2) {
    hl2_ = std::make_unique<system>();
    hl2_->components = 3;
    factorise(hl2_->ldlt, normal_matrix(design_matrix(points_, texels_, 3)));
  }
}

seam_stitcher::~seam_stitcher() = default;

void seam_stitcher::stitch(image& img, std::vector<std::uint8_t>& filled, const std::uint8_t* blocked, float lo, float hi) const {
  if (empty()) return;
  const std::vector<float> start = initial_values(img, filled, blocked, texels_);
  const auto ch = std::size_t(img.channels);
  const auto n = Eigen::Index(texels_.size());
  Eigen::MatrixXd rhs(n, Eigen::Index(ch));
  for (Eigen::Index u = 0; u < n; ++u)
    for (std::size_t c = 0; c < ch; ++c) rhs(u, Eigen::Index(c)) = stitch_regularization * double(start[std::size_t(u) * ch + c]);
  const Eigen::MatrixXd x = scalar_->ldlt.solve(rhs);
  for (Eigen::Index u = 0; u < n; ++u) {
    const std::size_t k = texels_[std::size_t(u)];
    for (std::size_t c = 0; c < ch; ++c) img.pixels[k * ch + c] = std::clamp(float(x(u, Eigen::Index(c))), lo, hi);
    filled[k] = 1;
  }
}

void seam_stitcher::stitch_hl2(std::array<image, 3>& hl2, std::vector<std::uint8_t>& filled, const std::uint8_t* blocked) const {
  if (empty()) return;
  std::array<std::vector<float>, 3> start;
  for (std::size_t j = 0; j < 3; ++j) start[j] = initial_values(hl2[j], filled, blocked, texels_);
  const auto n = Eigen::Index(texels_.size());
  Eigen::MatrixXd rhs(3 * n, 3);  // unknown 3u + k (basis k) per colour channel c
  for (Eigen::Index u = 0; u < n; ++u)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t c = 0; c < 3; ++c)
        rhs(3 * u + Eigen::Index(j), Eigen::Index(c)) = stitch_regularization * double(start[j][std::size_t(u) * 3 + c]);
  const Eigen::MatrixXd x = hl2_->ldlt.solve(rhs);
  for (Eigen::Index u = 0; u < n; ++u) {
    const std::size_t k = texels_[std::size_t(u)];
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t c = 0; c < 3; ++c)
        hl2[j].pixels[k * 3 + c] = std::max(0.0f, float(x(3 * u + Eigen::Index(j), Eigen::Index(c))));
    filled[k] = 1;
  }
}

}  // namespace hemilight::bake_detail
