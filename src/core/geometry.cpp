#include "hemilight/geometry.hpp"

#include "table_cache.hpp"

#include <algorithm>
#include <string>
#include <thread>

namespace hemilight {

namespace {

// Area-element formula: solid angle of [0, u] x [0, v] on the plane at distance 1 (signed).
double area_element(double u, double v) noexcept { return std::atan2(u * v, std::sqrt(u * u + v * v + 1.0)); }

}  // namespace

std::string hemicube_resolution_problem(int n, const std::string& name) {
  if (is_valid_hemicube_resolution(n)) return {};
  return name + " " + std::to_string(n) + " is invalid: it must be even and in [" + std::to_string(hemicube_min_resolution) +
         ", " + std::to_string(hemicube_max_resolution) + "]";
}

void check_hemicube_resolution(int n, const char* function, const std::string& name) {
  if (!is_valid_hemicube_resolution(n)) throw_invalid_argument(std::string(function) + ": " + hemicube_resolution_problem(n, name));
}

double rectangle_solid_angle(double u0, double v0, double u1, double v1) noexcept {
  return area_element(u1, v1) - area_element(u0, v1) - area_element(u1, v0) + area_element(u0, v0);
}

double lambert_projected_solid_angle(const glm::dvec3* dirs, std::size_t count, const glm::dvec3& n) noexcept {
  // E = 1/2 sum_i beta_i (n . gamma_i), beta_i the arc angle between consecutive vertices and
  // gamma_i the unit normal of their great circle. beta_i gamma_i = atan2(|c|, a.b) c / |c| with
  // c = a x b: atan2 keeps tiny arcs accurate where acos(a.b) would lose them to rounding.
  double sum = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const glm::dvec3& a = dirs[i];
    const glm::dvec3& b = dirs[(i + 1) % count];
    const glm::dvec3 c = glm::cross(a, b);
    const double len = glm::length(c);
    if (len == 0.0) continue;  // coincident or opposite vertices: an empty edge
    sum += std::atan2(len, glm::dot(a, b)) * glm::dot(n, c) / len;
  }
  return 0.5 * sum;
}

std::array<glm::dvec3, 4> hemicube_texel_corners(int n, std::size_t index) noexcept {
  const hemicube_texel t = hemicube_texel_from_index(n, index);
  const glm::dvec2 c0 = hemicube_texel_min_corner(n, t);
  const double s = 2.0 / n;
  return {glm::normalize(hemicube_face_point(t.face, c0.x, c0.y)),
          glm::normalize(hemicube_face_point(t.face, c0.x + s, c0.y)),
          glm::normalize(hemicube_face_point(t.face, c0.x + s, c0.y + s)),
          glm::normalize(hemicube_face_point(t.face, c0.x, c0.y + s))};
}

double hemicube_texel_solid_angle(int n, std::size_t index) noexcept {
  const hemicube_texel t = hemicube_texel_from_index(n, index);
  const glm::dvec2 c0 = hemicube_texel_min_corner(n, t);
  const double s = 2.0 / n;
  // Every face is a plane at distance 1 with (u, v) = (0, 0) at the foot of the perpendicular.
  return rectangle_solid_angle(c0.x, c0.y, c0.x + s, c0.y + s);
}

double hemicube_texel_projected_solid_angle(int n, std::size_t index) noexcept {
  const std::array<glm::dvec3, 4> corners = hemicube_texel_corners(n, index);
  return std::fabs(lambert_projected_solid_angle(corners.data(), corners.size(), glm::dvec3(0, 0, 1)));
}

hemicube_table::hemicube_table(int n) : n_(n) {
  if (!is_valid_hemicube_resolution(n))
    throw_invalid_argument("hemicube resolution " + std::to_string(n) + " is invalid: it must be even and in [" +
                           std::to_string(hemicube_min_resolution) + ", " +
                           std::to_string(hemicube_max_resolution) + "]");
  const std::size_t count = hemicube_texel_count(n);
  solid_angle_.resize(count);
  projected_solid_angle_.resize(count);
  auto fill = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      solid_angle_[i] = static_cast<float>(hemicube_texel_solid_angle(n, i));
      projected_solid_angle_[i] = static_cast<float>(hemicube_texel_projected_solid_angle(n, i));
    }
  };
  // Small tables are not worth a thread; large ones (N >= 256: 200k texels) split over cores.
  const std::size_t threads =
      count < (1u << 16) ? 1u : std::max<std::size_t>(1, std::thread::hardware_concurrency());
  if (threads == 1) {
    fill(0, count);
    return;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (count + threads - 1) / threads;
  for (std::size_t k = 0; k < threads; ++k)
    pool.emplace_back(fill, std::min(count, k * chunk), std::min(count, (k + 1) * chunk));
  for (std::thread& th : pool) th.join();
}

std::shared_ptr<const hemicube_table> hemicube_table::get(int n) {
  if (!is_valid_hemicube_resolution(n)) return std::make_shared<const hemicube_table>(n);  // throws
  // Kept in the process's table cache (table_cache.hpp: LRU within the budget of memory.hpp).
  return detail::cached_table<hemicube_table>(
      detail::table_kind::hemicube_weights, n, [n] { return std::make_shared<const hemicube_table>(n); },
      [](const hemicube_table& t) { return detail::vector_bytes(t.solid_angle_) + detail::vector_bytes(t.projected_solid_angle_); });
}

}  // namespace hemilight
