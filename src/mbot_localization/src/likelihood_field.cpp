#include "mbot_localization/likelihood_field.h"

#include <mbot_common/distance_transform.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot_localization
{
namespace
{
/// "No obstacle" for the transform: large but finite, so that differences stay finite.
constexpr double FAR = 1e20;
}  // namespace

std::vector<double> squaredDistanceTransform(const std::vector<uint8_t>& occupied, unsigned width, unsigned height)
{
  std::vector<double> grid(occupied.size());
  for (size_t i = 0; i < occupied.size(); ++i) grid[i] = occupied[i] ? 0.0 : FAR;

  // Scratch of the 1-D pass, sized once for the longer side and reused by every column and row.
  const unsigned longest = std::max(width, height);
  std::vector<double> f(longest), d(longest), z(longest + 1);
  std::vector<int> v(longest);

  // pass 1: along every column (y), then pass 2: along every row (x) on the column result
  for (unsigned x = 0; x < width; ++x)
  {
    for (unsigned y = 0; y < height; ++y) f[y] = grid[static_cast<size_t>(y) * width + x];
    mbot_common::squaredDistanceTransform1d(f.data(), static_cast<int>(height), d.data(), v.data(), z.data());
    for (unsigned y = 0; y < height; ++y) grid[static_cast<size_t>(y) * width + x] = d[y];
  }
  for (unsigned y = 0; y < height; ++y)
  {
    const size_t row = static_cast<size_t>(y) * width;
    for (unsigned x = 0; x < width; ++x) f[x] = grid[row + x];
    mbot_common::squaredDistanceTransform1d(f.data(), static_cast<int>(width), d.data(), v.data(), z.data());
    for (unsigned x = 0; x < width; ++x) grid[row + x] = d[x];
  }
  return grid;
}

LikelihoodField::LikelihoodField(const OccupancyGridData& grid, double max_distance)
    : width_(grid.width),
      height_(grid.height),
      resolution_(grid.resolution),
      origin_x_(grid.origin_x),
      origin_y_(grid.origin_y),
      max_distance_(max_distance)
{
  const size_t cells = static_cast<size_t>(width_) * height_;
  if (grid.data.size() != cells)
    throw std::invalid_argument("likelihood field: the map is " + std::to_string(width_) + " x " +
                                std::to_string(height_) + " cells but has " + std::to_string(grid.data.size()) +
                                " values");
  if (!(resolution_ > 0.0))
    throw std::invalid_argument("likelihood field: resolution must be > 0, got " + std::to_string(resolution_));
  if (!(max_distance_ > 0.0))
    throw std::invalid_argument("likelihood field: laser_likelihood_max_dist must be > 0, got " +
                                std::to_string(max_distance_));

  std::vector<uint8_t> occupied(cells);
  free_.resize(cells);
  for (size_t i = 0; i < cells; ++i)
  {
    occupied[i] = grid.data[i] > 50 ? 1 : 0;
    free_[i] = grid.data[i] == 0 ? 1 : 0;
  }
  const std::vector<double> squared = squaredDistanceTransform(occupied, width_, height_);
  distance_.resize(cells);
  for (size_t i = 0; i < cells; ++i)
    distance_[i] = static_cast<float>(std::min(std::sqrt(squared[i]) * resolution_, max_distance_));
}

bool LikelihoodField::worldToMap(double x, double y, unsigned& mx, unsigned& my) const
{
  const double fx = std::floor((x - origin_x_) / resolution_);
  const double fy = std::floor((y - origin_y_) / resolution_);
  if (!(fx >= 0.0 && fy >= 0.0 && fx < width_ && fy < height_)) return false;  // also NaN
  mx = static_cast<unsigned>(fx);
  my = static_cast<unsigned>(fy);
  return true;
}

double LikelihoodField::distance(double x, double y) const
{
  unsigned mx, my;
  if (!worldToMap(x, y, mx, my)) return max_distance_;
  return distance_[index(mx, my)];
}

double LikelihoodField::surfaceDistance(double x, double y) const
{
  // cell coordinates with 0 at the centre of cell 0
  const double fx = (x - origin_x_) / resolution_ - 0.5;
  const double fy = (y - origin_y_) / resolution_ - 0.5;
  if (!(fx > -0.5 && fy > -0.5 && fx < width_ - 0.5 && fy < height_ - 0.5)) return max_distance_;
  // the four cell centres around the point, clamped at the map's border
  const int x0 = std::clamp(static_cast<int>(std::floor(fx)), 0, static_cast<int>(width_) - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(fy)), 0, static_cast<int>(height_) - 1);
  const int x1 = std::min(x0 + 1, static_cast<int>(width_) - 1);
  const int y1 = std::min(y0 + 1, static_cast<int>(height_) - 1);
  const double tx = std::clamp(fx - x0, 0.0, 1.0), ty = std::clamp(fy - y0, 0.0, 1.0);
  const double bottom = (1.0 - tx) * cellDistance(x0, y0) + tx * cellDistance(x1, y0);
  const double top = (1.0 - tx) * cellDistance(x0, y1) + tx * cellDistance(x1, y1);
  const double d = (1.0 - ty) * bottom + ty * top;
  return std::max(0.0, d - 0.5 * resolution_);
}

bool LikelihoodField::isFree(double x, double y) const
{
  unsigned mx, my;
  return worldToMap(x, y, mx, my) && free_[index(mx, my)] != 0;
}

}  // namespace mbot_localization
