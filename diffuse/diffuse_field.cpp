#include "diffuse/diffuse_field.h"

#include <algorithm>
#include <cmath>
#include <mutex>

#include "core/error.h"
#include "core/math.h"

namespace nebula {

DiffuseField::DiffuseField(const DiffuseField& other)
    : cells(other.cells), shift(other.shift), degree(other.degree), zonal(other.zonal),
      zonal_stars(other.zonal_stars), response(other.response),
      response_tau_max(other.response_tau_max), packed_(other.packed_) {
  for (int k = 0; k < kMaxZonalStars; ++k) zonal_star[k] = other.zonal_star[k];
  device_packed.share(other.device_packed);
}

DiffuseField& DiffuseField::operator=(const DiffuseField& other) {
  if (this != &other) {
    DiffuseField copy(other);
    *this = std::move(copy);
  }
  return *this;
}

bool DiffuseField::has_harmonics() const {
  return packed_.size() == packed_size() || device_packed.holds(packed_size() * sizeof(float));
}

void DiffuseField::allocate(size_t bands, bool on_host) {
  if (bands > size_t(kMaxBands)) throw Error("diffuse field: at most " + std::to_string(kMaxBands) + " bands");
  packed_.clear();
  if (on_host) packed_.assign(packed_size(), 0.0f);
  response.assign(bands, {});
  response_tau_max.assign(bands, 0.0f);
  device_packed.reset();
  for (DeviceMirror& m : device_response) m.reset();
}

const std::vector<float>& DiffuseField::host_packed() const {
  // Fetched once, under a lock: two threads may render from one field.
  static std::mutex fetching;
  std::lock_guard<std::mutex> lock(fetching);
  if (packed_.size() != packed_size()) {
    std::vector<float> host(packed_size());
    device_packed.download(host.data(), host.size() * sizeof(float));
    packed_ = std::move(host);
  }
  return packed_;
}

std::vector<float>& DiffuseField::packed_for_writing() {
  host_packed();
  device_packed.reset();
  return packed_;
}

std::vector<float> DiffuseField::band_coeffs(size_t b) const {
  if (b >= size_t(kMaxBands)) throw Error("diffuse field: no band " + std::to_string(b));
  const std::vector<float>& packed = host_packed();
  const size_t n = packed.size() / 4;
  std::vector<float> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = packed[i * 4 + b];
  return out;
}

void DiffuseField::set_band_coeffs(size_t b, const std::vector<float>& coeffs) {
  std::vector<float>& packed = packed_for_writing();
  const size_t n = packed.size() / 4;
  if (b >= size_t(kMaxBands) || coeffs.size() != n)
    throw Error("diffuse field: band " + std::to_string(b) + " has the wrong size");
  for (size_t i = 0; i < n; ++i) packed[i * 4 + b] = coeffs[i];
}

size_t DiffuseField::bytes() const {
  size_t floats = packed_size() + response_tau_max.size();
  for (const auto& r : response) floats += r.size();
  return floats * sizeof(float);
}

DiffuseView DiffuseField::view(bool without_harmonics) const {
  DiffuseView v;
  v.cells = cells;
  v.shift = shift;
  v.degree = degree;
  v.coeffs = n_coeffs();
  v.stride = response_stride();
  v.own_at = n_zonal() > 0 ? diffuse_response_stride(zonal) : 0;
  v.zonal = n_zonal() > 0 ? zonal : 0;
  v.zonal_stars = n_zonal() > 0 ? zonal_stars : 0;
  for (int k = 0; k < kMaxZonalStars; ++k) v.zonal_star[k] = zonal_star[k];
  v.packed = without_harmonics ? nullptr : host_packed().data();
  for (size_t b = 0; b < response.size() && b < size_t(kMaxBands); ++b) {
    if (response[b].empty()) continue;
    v.has[b] = true;
    v.response[b] = response[b].data();
    v.rows[b] = static_cast<int>(response[b].size() / size_t(v.stride));
    v.rows_per_tau[b] = float(v.rows[b] - 1) / response_tau_max[b];
  }
  return v;
}

std::vector<double> legendre_moments(const ScatteringTable& table, int n) {
  const int n_tau = table.n_tau(), n_mu = table.n_mu();
  if (n_tau < 2 || table.P.size() != size_t(n_tau) * n_mu)
    throw Error("diffuse response: the scattering table has no rows");
  // integral over bin k of P_l(mu) d mu = [P_{l+1} - P_{l-1}] / (2l + 1) between the edges (l >= 1).
  std::vector<double> weight(size_t(n_mu) * (n + 1)), lo(n + 2), hi(n + 2);
  for (int k = 0; k < n_mu; ++k) {
    const double a = table.mu_edges[k], b = table.mu_edges[k + 1];
    legendre(n + 1, a, lo.data());
    legendre(n + 1, b, hi.data());
    weight[size_t(k) * (n + 1)] = b - a;
    for (int l = 1; l <= n; ++l)
      weight[size_t(k) * (n + 1) + l] = ((hi[l + 1] - hi[l - 1]) - (lo[l + 1] - lo[l - 1])) / (2.0 * l + 1.0);
  }
  std::vector<double> out(size_t(n_tau) * (n + 1));
  for (int i = 0; i < n_tau; ++i)
    for (int l = 0; l <= n; ++l) {
      double sum = 0;
      for (int k = 0; k < n_mu; ++k) sum += double(table.P[table.index(i, k)]) * weight[size_t(k) * (n + 1) + l];
      out[size_t(i) * (n + 1) + l] = 2.0 * kPiD * sum;
    }
  return out;
}

double lanczos_sigma(int l, int degree) {
  if (l == 0) return 1.0;
  const double x = kPiD * l / (degree + 1);
  return std::sin(x) / x;
}

std::vector<float> delta_m_response(const ScatteringTable& table, int degree, int zonal, DiffuseTaper taper) {
  if (degree < 0 || degree > kMaxDiffuseDegree)
    throw ParameterError("diffuse_order", "must be 0 to " + std::to_string(kMaxDiffuseDegree) + ", got " +
                                              std::to_string(degree));
  if (zonal > kMaxZonalDegree)
    throw ParameterError("diffuse_zonal", "must be at most " + std::to_string(kMaxZonalDegree));
  const bool has_zonal = zonal > degree;
  const int n = (has_zonal ? zonal : degree) + 1;
  const std::vector<double> p = legendre_moments(table, n);
  const int stride = has_zonal ? diffuse_zonal_stride(degree, zonal) : diffuse_response_stride(degree);
  const int own_at = has_zonal ? diffuse_response_stride(zonal) : 0;
  std::vector<float> out(size_t(table.n_tau()) * stride, 0.0f);
  const bool lanczos = resolved_taper(taper, degree, zonal) == DiffuseTaper::Lanczos;
  // p_l - p_{cut+1} (tapered: times sigma_l) for l <= cut, then the peak.
  auto put = [](const double* row, int cut, bool lanczos, float* o) {
    const double peak = std::max(0.0, row[cut + 1]);
    for (int l = 0; l <= cut; ++l)
      o[l] = static_cast<float>((row[l] - peak) * (lanczos ? lanczos_sigma(l, cut) : 1.0));
    o[cut + 1] = static_cast<float>(peak);
  };
  for (int i = 0; i < table.n_tau(); ++i) {
    const double* row = p.data() + size_t(i) * (n + 1);
    float* o = out.data() + size_t(i) * stride;
    if (has_zonal) put(row, zonal, lanczos, o);
    put(row, degree, lanczos, o + own_at);
  }
  return out;
}

GridShape diffuse_cells(const GridShape& grid, int cells, int* shift) {
  if (cells < 1) throw ParameterError("diffuse_cells", "must be at least 1, got " + std::to_string(cells));
  const int longest = std::max({grid.nx, grid.ny, grid.nz});
  int s = 0;
  while ((longest >> (s + 1)) >= cells && s < 16) ++s;
  const int f = 1 << s;
  GridShape c;
  c.nx = (grid.nx + f - 1) / f;
  c.ny = (grid.ny + f - 1) / f;
  c.nz = (grid.nz + f - 1) / f;
  c.origin = grid.origin;
  c.voxel = grid.voxel * float(f);
  if (shift) *shift = s;
  return c;
}

}  // namespace nebula
