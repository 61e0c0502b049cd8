/**
 * @file test_raycast.cpp
 * @brief Exact-geometry tests of the ray casting core: grid walls, circles, boxes, REP-117
 *        encoding, beam layout, and randomized comparisons against brute-force references.
 */
#include "mbot_sim/raycast.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace
{
using mbot_sim::Circle;
using mbot_sim::GridRaycaster;
using mbot_sim::OrientedBox;
using mbot_sim::ScanSpec;
using mbot_sim::ShapeSet;

const double kInf = std::numeric_limits<double>::infinity();

struct Cell
{
  int x, y;
};

GridRaycaster makeGrid(unsigned w, unsigned h, double res, double ox, double oy, const std::vector<Cell>& occupied)
{
  std::vector<uint8_t> cells(static_cast<size_t>(w) * h, 0);
  for (const Cell& c : occupied) cells[static_cast<size_t>(c.y) * w + c.x] = 1;
  return GridRaycaster(cells, w, h, res, ox, oy);
}

/// Reference: ray (x, y) + t (cos a, sin a) against the axis-aligned square [x0, x1] x [y0, y1]
/// by the slab method: entry distance (0 when starting inside), or +Inf on a miss.
double raySquare(double x, double y, double ux, double uy, double x0, double y0, double x1, double y1)
{
  double t_in = 0.0;
  double t_out = kInf;
  const double p[2] = {x, y};
  const double u[2] = {ux, uy};
  const double lo[2] = {x0, y0};
  const double hi[2] = {x1, y1};
  for (int a = 0; a < 2; ++a)
  {
    if (u[a] == 0.0)
    {
      if (p[a] < lo[a] || p[a] > hi[a]) return kInf;
      continue;
    }
    double t0 = (lo[a] - p[a]) / u[a];
    double t1 = (hi[a] - p[a]) / u[a];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  return t_in <= t_out ? t_in : kInf;
}

/// Reference: test the ray against every occupied cell of a grid, return the nearest entry.
double bruteForceGridCast(const std::vector<uint8_t>& cells, unsigned w, unsigned h, double res, double ox, double oy,
                          double x, double y, double theta, double max_range)
{
  const double ux = std::cos(theta);
  const double uy = std::sin(theta);
  double best = max_range;
  for (unsigned j = 0; j < h; ++j)
    for (unsigned i = 0; i < w; ++i)
      if (cells[static_cast<size_t>(j) * w + i])
      {
        const double t = raySquare(x, y, ux, uy, ox + i * res, oy + j * res, ox + (i + 1) * res, oy + (j + 1) * res);
        best = std::min(best, t);
      }
  return best;
}

/// Reference: ray against a convex polygon given by its corners, by intersecting every edge
/// as a segment (a different method from the slab test in the library). +Inf on a miss.
double rayPolygon(double x, double y, double ux, double uy, const std::vector<double>& px,
                  const std::vector<double>& py)
{
  double best = kInf;
  const size_t n = px.size();
  for (size_t k = 0; k < n; ++k)
  {
    const double ax = px[k], ay = py[k];
    const double ex = px[(k + 1) % n] - ax, ey = py[(k + 1) % n] - ay;
    // Solve (x, y) + t u = a + s e.
    const double den = ux * ey - uy * ex;
    if (std::abs(den) < 1e-15) continue;
    const double t = ((ax - x) * ey - (ay - y) * ex) / den;
    const double s = ((ax - x) * uy - (ay - y) * ux) / den;
    if (t >= 0.0 && s >= 0.0 && s <= 1.0) best = std::min(best, t);
  }
  return best;
}

std::vector<double> boxCornersX(const OrientedBox& b)
{
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double lx[4] = {b.half_length, -b.half_length, -b.half_length, b.half_length};
  const double ly[4] = {b.half_width, b.half_width, -b.half_width, -b.half_width};
  std::vector<double> out;
  for (int k = 0; k < 4; ++k) out.push_back(b.x + c * lx[k] - s * ly[k]);
  return out;
}

std::vector<double> boxCornersY(const OrientedBox& b)
{
  const double c = std::cos(b.yaw), s = std::sin(b.yaw);
  const double lx[4] = {b.half_length, -b.half_length, -b.half_length, b.half_length};
  const double ly[4] = {b.half_width, b.half_width, -b.half_width, -b.half_width};
  std::vector<double> out;
  for (int k = 0; k < 4; ++k) out.push_back(b.y + s * lx[k] + c * ly[k]);
  return out;
}

/// Reference: ray against a circle by solving |p + t u - c| = r for the smaller root.
double rayCircleRef(double x, double y, double ux, double uy, const Circle& c)
{
  const double fx = x - c.x, fy = y - c.y;
  const double b = fx * ux + fy * uy;
  const double cc = fx * fx + fy * fy - c.radius * c.radius;
  const double disc = b * b - cc;
  if (disc < 0.0) return kInf;
  const double t = -b - std::sqrt(disc);
  return t >= 0.0 ? t : kInf;
}

ScanSpec oneBeam(double x, double y, double yaw, double range_max)
{
  ScanSpec s;
  s.x = x;
  s.y = y;
  s.yaw = yaw;
  s.beams = 1;
  s.range_min = 0.0;
  s.range_max = range_max;
  return s;
}

/// An empty 10 x 10 m grid around the origin, for shape-only tests.
GridRaycaster emptyGrid() { return makeGrid(200, 200, 0.05, -5.0, -5.0, {}); }
}  // namespace

// ---------------------------------------------------------------------------------------------
// Grid
// ---------------------------------------------------------------------------------------------

TEST(GridRaycaster, WallTwoMetresAwayReadsTwoMinusHalfACell)
{
  // 0.05 m cells, origin off zero. The sensor sits at the centre of cell (60, 60); walls are
  // cells whose centres are 2 m = 40 cells away in each direction.
  const double res = 0.05, ox = -3.2, oy = 1.7;
  std::vector<Cell> walls;
  for (int k = 0; k < 121; ++k)
  {
    walls.push_back({100, k});
    walls.push_back({20, k});
    walls.push_back({k, 100});
    walls.push_back({k, 20});
  }
  const GridRaycaster grid = makeGrid(121, 121, res, ox, oy, walls);
  const double x = ox + 60.5 * res, y = oy + 60.5 * res;
  const double expected = 2.0 - 0.5 * res;
  EXPECT_NEAR(grid.cast(x, y, 0.0, 8.0), expected, 1e-6);
  EXPECT_NEAR(grid.cast(x, y, M_PI / 2, 8.0), expected, 1e-6);
  EXPECT_NEAR(grid.cast(x, y, M_PI, 8.0), expected, 1e-6);
  EXPECT_NEAR(grid.cast(x, y, -M_PI / 2, 8.0), expected, 1e-6);
  // Shorter max range: nothing within it.
  EXPECT_EQ(grid.cast(x, y, 0.0, 1.5), 1.5);
  EXPECT_TRUE(grid.occupiedAt(ox + 100.5 * res, y));
  EXPECT_FALSE(grid.occupiedAt(x, y));
}

TEST(GridRaycaster, SingleCellAlongDiagonalsHitsTheCorner)
{
  // One occupied cell (20, 20); the sensor at cell centres on the four diagonals.
  const double res = 0.1;
  const GridRaycaster grid = makeGrid(41, 41, res, 0.0, 0.0, {{20, 20}});
  // From (10.5, 10.5) cells towards +x+y: enters the cell through its corner (20, 20).
  const double d = 9.5 * std::sqrt(2.0) * res;
  EXPECT_NEAR(grid.cast(10.5 * res, 10.5 * res, M_PI / 4, 8.0), d, 1e-9);
  // From (30.5, 30.5) towards -x-y: enters through corner (21, 21).
  EXPECT_NEAR(grid.cast(30.5 * res, 30.5 * res, -3 * M_PI / 4, 8.0), d, 1e-9);
  EXPECT_NEAR(grid.cast(30.5 * res, 10.5 * res, 3 * M_PI / 4, 8.0), d, 1e-9);
  EXPECT_NEAR(grid.cast(10.5 * res, 30.5 * res, -M_PI / 4, 8.0), d, 1e-9);
}

TEST(GridRaycaster, SingleCellAtOddAnglesMatchesAnalyticSquare)
{
  const double res = 0.05;
  const int cx = 37, cy = 23;
  const GridRaycaster grid = makeGrid(80, 60, res, 0.0, 0.0, {{cx, cy}});
  const double x0 = cx * res, y0 = cy * res, x1 = x0 + res, y1 = y0 + res;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0.0, 80 * res), uy(0.0, 60 * res);
  std::uniform_real_distribution<double> in_cell(0.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 2000; ++k)
  {
    const double x = ux(rng), y = uy(rng);
    // Aim at a random point of the cell, so that most rays hit it at odd angles.
    const double tx = x0 + in_cell(rng) * res, ty = y0 + in_cell(rng) * res;
    const double theta = std::atan2(ty - y, tx - x);
    const double expected = std::min(8.0, raySquare(x, y, std::cos(theta), std::sin(theta), x0, y0, x1, y1));
    const double got = grid.cast(x, y, theta, 8.0);
    ASSERT_NEAR(got, expected, 1e-9) << "ray from (" << x << ", " << y << ") at " << theta;
    hits += expected < 8.0 ? 1 : 0;
  }
  EXPECT_EQ(hits, 2000);
}

TEST(GridRaycaster, OriginOutsideTheGridAndRaysLeavingIt)
{
  const double res = 0.05;
  // A 5 x 5 m grid at the origin with one wall column at x = 4 m (cells 80).
  std::vector<Cell> walls;
  for (int k = 0; k < 100; ++k) walls.push_back({80, k});
  const GridRaycaster grid = makeGrid(100, 100, res, 0.0, 0.0, walls);
  // Outside, looking away: max range.
  EXPECT_EQ(grid.cast(-1.0, 2.0, M_PI, 8.0), 8.0);
  // Outside, looking into the grid: outside is free, the ray enters and hits the wall.
  EXPECT_NEAR(grid.cast(-1.0, 2.0, 0.0, 8.0), 5.0, 1e-9);
  // Outside, passing beside the grid: max range.
  EXPECT_EQ(grid.cast(-1.0, 6.0, 0.0, 8.0), 8.0);
  // Inside, leaving the grid without a hit (through the bottom edge): max range.
  EXPECT_EQ(grid.cast(1.0, 2.0, -M_PI / 2, 8.0), 8.0);
  // Inside, a wall beyond max range.
  EXPECT_EQ(grid.cast(1.0, 2.0, 0.0, 2.5), 2.5);
  // Starting inside a wall reads 0.
  EXPECT_EQ(grid.cast(4.02, 2.0, 0.3, 8.0), 0.0);
  // Outside and the rest of the grid is empty: free.
  const GridRaycaster empty = makeGrid(10, 10, res, 0.0, 0.0, {});
  EXPECT_EQ(empty.cast(0.1, 0.1, 0.7, 8.0), 8.0);
}

TEST(GridRaycaster, ClearanceIsTheSquareToSquareDistance)
{
  // clearanceAt must never exceed the smallest distance between the cell's square and any
  // occupied square (that is what makes the long steps safe), and is stored rounded down to a
  // quarter cell, so it is at most a quarter cell less.
  const double res = 0.1;
  const std::vector<Cell> occ = {{5, 5}, {6, 5}, {20, 14}, {3, 17}};
  const GridRaycaster grid = makeGrid(30, 20, res, 0.0, 0.0, occ);
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 30; ++i)
    {
      double best = kInf;
      for (const Cell& c : occ)
      {
        const double gx = std::max(std::abs(i - c.x) - 1.0, 0.0);
        const double gy = std::max(std::abs(j - c.y) - 1.0, 0.0);
        best = std::min(best, std::hypot(gx, gy));
      }
      const double got = grid.clearanceAt((i + 0.5) * res, (j + 0.5) * res);
      ASSERT_LE(got, best * res) << "cell " << i << ", " << j;
      ASSERT_GT(got, (best - 0.25 - 1e-3) * res) << "cell " << i << ", " << j;
    }
}

TEST(GridRaycaster, QuadrantClearanceIgnoresOnlyWallsBehind)
{
  // A ray heading into a quadrant (here: +x, +y and -x, -y) can only enter cells at or ahead
  // of its cell on both axes. clearanceAlong must never exceed the distance to the occupied
  // cells there (safety), and is the larger of the clearances over the cells ahead on x and
  // ahead on y (rounded down to a quarter cell).
  const double res = 0.1;
  const int w = 40, h = 30;
  std::mt19937 rng(11);
  std::bernoulli_distribution sparse(0.03);
  std::vector<Cell> occ;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      if (sparse(rng)) occ.push_back({i, j});
  const GridRaycaster grid = makeGrid(w, h, res, 0.0, 0.0, occ);
  auto gap = [](int d) { return std::max(std::abs(d) - 1.0, 0.0); };
  int longer = 0;
  for (int sign : {1, -1})
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
      {
        bool wall = false;
        double ahead_both = kInf, ahead_x = kInf, ahead_y = kInf, any = kInf;
        for (const Cell& c : occ)
        {
          wall = wall || (c.x == i && c.y == j);
          const double d = std::hypot(gap(c.x - i), gap(c.y - j));
          const bool ax = sign * (c.x - i) >= 0, ay = sign * (c.y - j) >= 0;
          any = std::min(any, d);
          if (ax) ahead_x = std::min(ahead_x, d);
          if (ay) ahead_y = std::min(ahead_y, d);
          if (ax && ay) ahead_both = std::min(ahead_both, d);
        }
        const double got = grid.clearanceAlong((i + 0.5) * res, (j + 0.5) * res, sign, sign) / res;
        if (wall)
        {
          ASSERT_EQ(got, 0.0);
          continue;
        }
        const double expected = std::min(std::max(ahead_x, ahead_y), 63.75);
        ASSERT_LE(got, ahead_both) << "cell " << i << ", " << j;  // a jump this long is safe
        ASSERT_LE(got, expected) << "cell " << i << ", " << j;
        ASSERT_GT(got, expected - 0.25 - 1e-3) << "cell " << i << ", " << j;
        longer += got > any + 1.0 ? 1 : 0;
      }
  EXPECT_GT(longer, 500);  // ignoring the walls behind really makes jumps longer
}

TEST(GridRaycaster, RandomRaysMatchBruteForce)
{
  // 10,000 random rays in a random grid with scattered cells, blocks and a diagonal wall;
  // origins also outside the grid and inside walls; every range must equal the per-cell
  // analytic reference within 1e-5 m.
  const unsigned w = 90, h = 70;
  const double res = 0.05, ox = -1.3, oy = 0.4;
  std::mt19937 rng(42);
  std::vector<uint8_t> cells(w * h, 0);
  std::bernoulli_distribution sparse(0.02);
  for (auto& c : cells) c = sparse(rng) ? 1 : 0;
  for (int k = 10; k < 60; ++k) cells[static_cast<size_t>(k) * w + k] = 1;  // diagonal staircase
  for (int y = 30; y < 38; ++y)
    for (int x = 60; x < 75; ++x) cells[static_cast<size_t>(y) * w + x] = 1;  // a block
  const GridRaycaster grid(cells, w, h, res, ox, oy);

  std::uniform_real_distribution<double> ux(ox - 0.5, ox + w * res + 0.5);
  std::uniform_real_distribution<double> uy(oy - 0.5, oy + h * res + 0.5);
  std::uniform_real_distribution<double> ua(-M_PI, M_PI);
  std::uniform_real_distribution<double> ur(0.1, 6.0);
  int hits = 0;
  for (int k = 0; k < 10000; ++k)
  {
    const double x = ux(rng), y = uy(rng), theta = ua(rng), max_range = ur(rng);
    const double expected = bruteForceGridCast(cells, w, h, res, ox, oy, x, y, theta, max_range);
    const double got = grid.cast(x, y, theta, max_range);
    ASSERT_NEAR(got, expected, 1e-5) << "ray " << k << " from (" << x << ", " << y << ") at " << theta << " max "
                                     << max_range;
    hits += expected < max_range ? 1 : 0;
  }
  // The test is only meaningful if many rays hit something (about half do).
  EXPECT_GT(hits, 4000);
}

TEST(GridRaycaster, NearlyAxisParallelRaysAtCellBoundariesMatchBruteForce)
{
  // Rays starting within 1e-8 cells of a cell boundary and running almost along it, between
  // two columns (and two rows) of scattered walls: the tracer must never place such a ray in
  // the neighbouring cell ahead (it would skip walls of the column the ray is really in).
  // Cell size and offsets are powers of two, so that every start point is exact and the
  // reference and the tracer see the same geometry (with a tilt of 1e-12 rad, rounding the
  // start by 1e-15 cells would move the crossing of the boundary by 1e-3 cells).
  const unsigned w = 40, h = 40;
  const double res = 0.0625;
  std::mt19937 rng(5);
  std::vector<uint8_t> cells(w * h, 0);
  std::bernoulli_distribution wall(0.15);
  for (unsigned k = 0; k < 40; ++k)
  {
    cells[k * w + 19] = wall(rng);  // columns 19 and 20, rows 19 and 20
    cells[k * w + 20] = wall(rng);
    cells[19 * w + k] = wall(rng);
    cells[20 * w + k] = wall(rng);
  }
  const GridRaycaster grid(cells, w, h, res, 0.0, 0.0);
  const double tilts[] = {0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-7, -1e-7, 1e-4, -1e-4};
  const double offsets[] = {-std::ldexp(1.0, -27), -std::ldexp(1.0, -40), 0.0, std::ldexp(1.0, -40),
                            std::ldexp(1.0, -27)};  // [cells]
  int hits = 0, rays = 0;
  for (double along : {2.5, 13.75, 37.5})  // [cells] where on the boundary the ray starts
    for (double off : offsets)
      for (double tilt : tilts)
        for (double axis : {0.0, 0.5 * M_PI, M_PI, 1.5 * M_PI})
        {
          const bool vertical = std::abs(std::sin(axis)) > 0.5;
          // Vertical rays start on the boundary x = 20 cells; horizontal ones on y = 20.
          const double x = (vertical ? 20.0 + off : along) * res;
          const double y = (vertical ? along : 20.0 + off) * res;
          if (grid.occupiedAt(x, y)) continue;
          const double theta = axis + tilt;
          const double expected = bruteForceGridCast(cells, w, h, res, 0.0, 0.0, x, y, theta, 3.0);
          const double got = grid.cast(x, y, theta, 3.0);
          ++rays;
          if (expected < 3.0) ++hits;
          // A ray starting exactly on a boundary may touch a wall's edge at t = 0, or run along
          // it: a tie, which the reference calls a hit and the tracer may not.
          if (off == 0.0) continue;
          ASSERT_NEAR(got, expected, 1e-5) << "from (" << x / res << ", " << y / res << ") cells at " << theta;
        }
  EXPECT_GT(rays, 400);
  EXPECT_GT(hits, 200);
}

/// Reference for a ray given by its direction (ux, uy) rather than an angle.
double bruteForceGridCastDir(const std::vector<uint8_t>& cells, unsigned w, unsigned h, double res, double x, double y,
                             double ux, double uy, double max_range)
{
  double best = max_range;
  for (unsigned j = 0; j < h; ++j)
    for (unsigned i = 0; i < w; ++i)
      if (cells[static_cast<size_t>(j) * w + i])
        best = std::min(best, raySquare(x, y, ux, uy, i * res, j * res, (i + 1) * res, (j + 1) * res));
  return best;
}

TEST(GridRaycaster, FanBeamGroupsMatchBruteForce)
{
  // castFan traces beams in groups (long steps interleaved), then the leftover beams one by
  // one, with the sensor cell's clearances looked up once per fan. Fans of every length modulo
  // the group size, directions with exact zero (and -0.0) components and exactly diagonal ones
  // mixed with random ones, sensors anywhere (also right next to walls), and max ranges that
  // end in open space, right at walls and beyond the grid (no outer walls: rays leave it).
  const unsigned w = 70, h = 50;
  const double res = 0.05;
  std::mt19937 rng(17);
  std::vector<uint8_t> cells(w * h, 0);
  std::bernoulli_distribution sparse(0.03);
  for (auto& c : cells) c = sparse(rng) ? 1 : 0;
  for (int k = 5; k < 40; ++k) cells[static_cast<size_t>(k) * w + k + 10] = 1;  // a diagonal staircase
  for (unsigned y = 20; y < 24; ++y)
    for (unsigned x = 40; x < 65; ++x) cells[y * w + x] = 1;  // a block
  const GridRaycaster grid(cells, w, h, res, 0.0, 0.0);

  const double d = std::sqrt(0.5);
  const std::vector<std::pair<double, double>> special = {{1.0, 0.0},  {0.0, 1.0},  {-1.0, 0.0},  {0.0, -1.0},
                                                          {-0.0, 1.0}, {1.0, -0.0}, {-1.0, -0.0}, {-0.0, -1.0},
                                                          {d, d},      {-d, d},     {-d, -d},     {d, -d}};
  std::uniform_real_distribution<double> ux(0.0, w * res), uy(0.0, h * res);
  std::uniform_real_distribution<double> ua(-M_PI, M_PI), ur(0.02, 5.0);
  std::uniform_int_distribution<int> un(1, 23);
  int rays = 0, hits = 0, next_to_wall = 0;
  for (int fan = 0; fan < 400; ++fan)
  {
    double x = ux(rng), y = uy(rng);
    if (fan % 4 == 0)
    {
      // Next to a wall: move right to the first free cell with a wall on its right, then
      // within 1e-7 cells of that wall.
      unsigned cx = static_cast<unsigned>(x / res);
      const unsigned cy = static_cast<unsigned>(y / res);
      while (cx + 1 < w && !(!cells[cy * w + cx] && cells[cy * w + cx + 1])) ++cx;
      if (cx + 1 < w)
      {
        x = (cx + 1 - 1e-7) * res;
        ++next_to_wall;
      }
    }
    if (grid.occupiedAt(x, y)) continue;
    const int n = un(rng);
    std::vector<double> dx(n), dy(n), got(n);
    for (int i = 0; i < n; ++i)
    {
      if (i % 3 == 0)
      {
        const auto& u = special[(fan + i) % special.size()];
        dx[i] = u.first;
        dy[i] = u.second;
      }
      else
      {
        const double a = ua(rng);
        dx[i] = std::cos(a);
        dy[i] = std::sin(a);
      }
    }
    const double max_range = fan % 5 == 0 ? 10.0 : ur(rng);  // 10 m: beyond the grid
    grid.castFan(x, y, dx.data(), dy.data(), n, max_range, got.data());
    for (int i = 0; i < n; ++i)
    {
      const double expected = bruteForceGridCastDir(cells, w, h, res, x, y, dx[i], dy[i], max_range);
      ASSERT_NEAR(got[i], expected, 1e-9) << "fan " << fan << " beam " << i << " of " << n << " from (" << x << ", "
                                          << y << ") along (" << dx[i] << ", " << dy[i] << ") max " << max_range;
      // The single-ray call takes the other path (no group) and must agree.
      ASSERT_NEAR(grid.castDirection(x, y, dx[i], dy[i], max_range), expected, 1e-9);
      ++rays;
      hits += expected < max_range ? 1 : 0;
    }
  }
  EXPECT_GT(rays, 3000);
  EXPECT_GT(next_to_wall, 50);
  EXPECT_GT(hits, rays / 3);
  EXPECT_LT(hits, rays - rays / 10);  // and some reach max range or leave the grid
}

TEST(GridRaycaster, FanEdgeCases)
{
  // A 4 x 4 m room (0.1 m cells) with one-cell walls on all sides and a wall cell at (20, 10).
  const double res = 0.1;
  std::vector<Cell> walls = {{20, 10}};
  for (int k = 0; k < 40; ++k)
  {
    walls.push_back({k, 0});
    walls.push_back({k, 39});
    walls.push_back({0, k});
    walls.push_back({39, k});
  }
  const GridRaycaster grid = makeGrid(40, 40, res, 0.0, 0.0, walls);
  const double d = std::sqrt(0.5);
  // Eight beams at 0, 45, ..., 315 degrees from the centre of cell (10, 10): the diagonal ones
  // run exactly through cell corners to the corner wall cells.
  const double dx[8] = {1, d, 0, -d, -1, -d, 0, d};
  const double dy[8] = {0, d, 1, d, 0, -d, -1, -d};
  double got[8];
  grid.castFan(1.05, 1.05, dx, dy, 8, 8.0, got);
  EXPECT_NEAR(got[0], 0.95, 1e-12);  // to the wall cell (20, 10)
  EXPECT_NEAR(got[2], 2.85, 1e-12);  // to the top wall (y = 3.9 m)
  EXPECT_NEAR(got[4], 0.95, 1e-12);  // to the left wall (x = 0.1 m)
  EXPECT_NEAR(got[6], 0.95, 1e-12);
  EXPECT_NEAR(got[1], 2.85 * std::sqrt(2.0), 1e-9);  // corner (3.9, 3.9)
  EXPECT_NEAR(got[5], 0.95 * std::sqrt(2.0), 1e-9);  // corner (0.1, 0.1)
  // Right next to a wall: the sensor a hair left of the wall cell (20, 10).
  grid.castFan(2.0 - 1e-9, 1.05, dx, dy, 8, 8.0, got);
  EXPECT_NEAR(got[0], 1e-9, 1e-12);
  EXPECT_NEAR(got[4], 1.9 - 1e-9, 1e-9);
  // Max range just short of, and just past, the wall at 0.95 m.
  grid.castFan(1.05, 1.05, dx, dy, 1, 0.95 - 1e-9, got);
  EXPECT_EQ(got[0], 0.95 - 1e-9);
  grid.castFan(1.05, 1.05, dx, dy, 1, 0.95 + 1e-9, got);
  EXPECT_NEAR(got[0], 0.95, 1e-12);
  // Without the room's walls, beams leave the grid (through edges and corners): max range.
  const GridRaycaster open_grid = makeGrid(40, 40, res, 0.0, 0.0, {{20, 10}});
  open_grid.castFan(1.05, 1.05, dx, dy, 8, 8.0, got);
  EXPECT_NEAR(got[0], 0.95, 1e-12);
  for (int i = 1; i < 8; ++i) EXPECT_EQ(got[i], 8.0) << "beam " << i;
  // A sensor on the grid's edge looking out along it.
  EXPECT_EQ(open_grid.castDirection(0.0, 1.0, -1.0, 0.0, 8.0), 8.0);
  EXPECT_EQ(open_grid.castDirection(0.0, 1.0, 0.0, 1.0, 8.0), 8.0);
}

TEST(GridRaycaster, RejectsInconsistentInput)
{
  EXPECT_THROW(GridRaycaster(std::vector<uint8_t>(10, 0), 4, 4, 0.05, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(GridRaycaster(std::vector<uint8_t>(16, 0), 4, 4, 0.0, 0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(ShapeSet(0.0), std::invalid_argument);
  const GridRaycaster grid = makeGrid(4, 4, 0.05, 0.0, 0.0, {{1, 1}});
  EXPECT_THROW(grid.cast(0.1, 0.1, std::nan(""), 1.0), std::invalid_argument);
  EXPECT_EQ(grid.cast(std::nan(""), 0.1, 0.0, 1.0), 1.0);  // no position: no return
}

// ---------------------------------------------------------------------------------------------
// Shapes and scans
// ---------------------------------------------------------------------------------------------

TEST(CastScan, CircleAtThreeMetresReadsTwoAndAHalf)
{
  const GridRaycaster grid = emptyGrid();
  ShapeSet shapes;
  Circle c;
  c.x = 3.0;
  c.radius = 0.5;
  shapes.addCircle(c);
  EXPECT_EQ(shapes.size(), 1u);
  std::vector<float> ranges;
  castScan(grid, shapes, oneBeam(0.0, 0.0, 0.0, 8.0), ranges);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_NEAR(ranges[0], 2.5, 1e-6);
  // Off-centre beam: the analytic chord entry.
  const double a = 0.1;
  castScan(grid, shapes, oneBeam(0.0, 0.0, a, 8.0), ranges);
  EXPECT_NEAR(ranges[0], 3.0 * std::cos(a) - std::sqrt(0.25 - std::pow(3.0 * std::sin(a), 2)), 1e-6);
  // Just past the tangent (asin(0.5 / 3) = 0.1674 rad): no return.
  castScan(grid, shapes, oneBeam(0.0, 0.0, 0.17, 8.0), ranges);
  EXPECT_EQ(ranges[0], std::numeric_limits<float>::infinity());
}

TEST(CastScan, BoxRotated45DegreesReadsTheAnalyticDistance)
{
  const GridRaycaster grid = emptyGrid();
  ShapeSet shapes;
  OrientedBox b;
  b.x = 3.0;
  b.y = 0.0;
  b.yaw = M_PI / 4;
  b.half_length = 0.5;
  b.half_width = 0.3;
  shapes.addBox(b);
  std::vector<float> ranges;
  const std::vector<double> px = boxCornersX(b), py = boxCornersY(b);
  castScan(grid, shapes, oneBeam(0.0, 0.0, 0.0, 8.0), ranges);
  // By hand, straight at the centre: a point (x, 0) is at x' = (x - 3) cos45, y' = -(x - 3)
  // sin45 in the box frame, inside when |x'| <= 0.5 and |y'| <= 0.3, i.e. |x - 3| <= 0.3 sqrt2.
  EXPECT_NEAR(ranges[0], 3.0 - 0.3 * std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(ranges[0], rayPolygon(0, 0, 1, 0, px, py), 1e-6);
  // Many beams at odd angles from another point: each equals the polygon reference.
  ScanSpec s;
  s.x = 0.4;
  s.y = -1.1;
  s.beams = 720;
  s.min_angle = -M_PI;
  s.angle_increment = 2 * M_PI / 720;
  s.range_max = 8.0;
  castScan(grid, shapes, s, ranges);
  int hits = 0;
  for (int i = 0; i < s.beams; ++i)
  {
    const double a = s.yaw + s.min_angle + i * s.angle_increment;
    const double expected = rayPolygon(s.x, s.y, std::cos(a), std::sin(a), px, py);
    if (expected < 8.0)
    {
      ++hits;
      EXPECT_NEAR(ranges[i], expected, 1e-5) << "beam " << i;
    }
    else
    {
      EXPECT_EQ(ranges[i], std::numeric_limits<float>::infinity()) << "beam " << i;
    }
  }
  EXPECT_GT(hits, 10);
}

TEST(CastScan, OwnBodyIsNotSeen)
{
  const GridRaycaster grid = emptyGrid();
  ShapeSet shapes;
  Circle self;
  self.radius = 0.15;
  self.owner = 3;
  shapes.addCircle(self);
  Circle other;
  other.x = -2.0;
  other.radius = 0.15;
  other.owner = 4;
  shapes.addCircle(other);
  ScanSpec s;
  s.beams = 4;
  s.angle_increment = M_PI / 2;  // beams along +x, +y, -x, -y
  s.range_min = 0.05;
  s.range_max = 8.0;
  s.ignore_owner = 3;
  std::vector<float> ranges;
  castScan(grid, shapes, s, ranges);
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(ranges[0], inf);
  EXPECT_EQ(ranges[1], inf);
  EXPECT_NEAR(ranges[2], 1.85, 1e-6);  // the other robot is seen
  EXPECT_EQ(ranges[3], inf);
  // Without ignoring its owner, the sensor sits inside the circle: every beam reads 0, which
  // is closer than range_min.
  s.ignore_owner = -1;
  castScan(grid, shapes, s, ranges);
  for (float r : ranges) EXPECT_EQ(r, -inf);
}

TEST(CastScan, Rep117InfinitiesAndWalls)
{
  // A wall column 3 m in front of the sensor.
  std::vector<Cell> walls;
  for (int k = 0; k < 200; ++k) walls.push_back({160, k});  // x in [3.0, 3.05]
  const GridRaycaster grid = makeGrid(200, 200, 0.05, -5.0, -5.0, walls);
  ShapeSet shapes;
  Circle near;
  near.x = -0.2;
  near.radius = 0.05;  // 0.15 m away behind the sensor
  shapes.addCircle(near);
  ScanSpec s;
  s.beams = 2;
  s.angle_increment = M_PI;  // +x and -x
  s.range_min = 0.2;
  s.range_max = 8.0;
  std::vector<float> ranges;
  castScan(grid, shapes, s, ranges);
  EXPECT_NEAR(ranges[0], 3.0, 1e-6);
  EXPECT_EQ(ranges[1], -std::numeric_limits<float>::infinity());  // closer than range_min
  s.range_max = 2.5;
  castScan(grid, shapes, s, ranges);
  EXPECT_EQ(ranges[0], std::numeric_limits<float>::infinity());  // wall beyond range_max
  // A circle in front of the wall wins; a circle behind it is hidden.
  Circle front, behind;
  front.x = 2.0;
  front.radius = 0.25;
  behind.x = 3.6;
  behind.y = 1.0;
  behind.radius = 0.5;
  shapes.addCircle(front);
  shapes.addCircle(behind);
  s.range_max = 8.0;
  s.beams = 1;
  castScan(grid, shapes, s, ranges);
  EXPECT_NEAR(ranges[0], 1.75, 1e-6);
  s.yaw = std::atan2(1.0, 3.6);  // towards the hidden circle's centre
  castScan(grid, shapes, s, ranges);
  EXPECT_NEAR(ranges[0], 3.0 / std::cos(s.yaw), 1e-5);  // the wall
  // Sensor outside the grid, rays leaving the grid: +Inf.
  ScanSpec out = oneBeam(-7.0, 0.0, M_PI, 8.0);
  castScan(grid, ShapeSet(), out, ranges);
  EXPECT_EQ(ranges[0], std::numeric_limits<float>::infinity());
}

TEST(CastScan, BeamLayoutFollowsYawMinAngleAndIncrement)
{
  const GridRaycaster grid = emptyGrid();
  // A tiny circle exactly on beam 123's direction.
  ScanSpec s;
  s.x = 0.3;
  s.y = -0.2;
  s.yaw = 1.0;
  s.min_angle = -2.0;
  s.angle_increment = 0.01;
  s.beams = 400;
  s.range_max = 8.0;
  const double a = s.yaw + s.min_angle + 123 * s.angle_increment;
  ShapeSet shapes;
  Circle c;
  c.x = s.x + 3.0 * std::cos(a);
  c.y = s.y + 3.0 * std::sin(a);
  c.radius = 0.001;
  shapes.addCircle(c);
  std::vector<float> ranges;
  castScan(grid, shapes, s, ranges);
  ASSERT_EQ(ranges.size(), 400u);
  for (int i = 0; i < s.beams; ++i)
  {
    if (i == 123)
      EXPECT_NEAR(ranges[i], 2.999, 1e-6);
    else
      EXPECT_EQ(ranges[i], std::numeric_limits<float>::infinity()) << "beam " << i;
  }
  // The same with a negative increment: the circle sits on beam 77 now.
  s.angle_increment = -0.01;
  s.min_angle = 0.5;
  const double b = s.yaw + s.min_angle + 77 * s.angle_increment;
  shapes.clear();
  EXPECT_EQ(shapes.size(), 0u);
  c.x = s.x + 3.0 * std::cos(b);
  c.y = s.y + 3.0 * std::sin(b);
  shapes.addCircle(c);
  castScan(grid, shapes, s, ranges);
  for (int i = 0; i < s.beams; ++i)
  {
    if (i == 77)
      EXPECT_NEAR(ranges[i], 2.999, 1e-6);
    else
      EXPECT_EQ(ranges[i], std::numeric_limits<float>::infinity()) << "beam " << i;
  }
}

TEST(CastScan, ManyLaserLayoutsInTurnEachReadRight)
{
  // Lasers of different models take turns (more layouts than castScan keeps cached): each
  // scan must use its own beam layout.
  const GridRaycaster grid = emptyGrid();
  ShapeSet shapes;
  Circle c;
  c.x = 2.0;
  c.radius = 0.05;
  shapes.addCircle(c);
  std::vector<float> ranges;
  for (int round = 0; round < 2; ++round)
    for (int layout = 0; layout < 12; ++layout)
    {
      ScanSpec s;
      s.beams = 100 + layout;
      s.angle_increment = 0.001 * (layout + 1);
      s.min_angle = -40 * s.angle_increment;  // beam 40 points along +x, at the circle
      s.range_max = 8.0;
      castScan(grid, shapes, s, ranges);
      ASSERT_EQ(ranges.size(), static_cast<size_t>(s.beams));
      EXPECT_NEAR(ranges[40], 1.95, 1e-6) << "layout " << layout;
      EXPECT_EQ(ranges[40 + 26], std::numeric_limits<float>::infinity()) << "layout " << layout;
    }
}

TEST(CastScan, ShapeAcrossTheScanSeamIsSeenByFirstAndLastBeams)
{
  // A full turn of 360 beams starting at -pi: a circle straight behind the sensor covers the
  // last beams and the first ones.
  const GridRaycaster grid = emptyGrid();
  ShapeSet shapes;
  Circle c;
  c.x = -2.0;
  c.radius = 0.1;
  shapes.addCircle(c);
  ScanSpec s;
  s.beams = 360;
  s.min_angle = -M_PI + 0.5 * M_PI / 180;  // beams at -179.5, -178.5, ..., 179.5 degrees
  s.angle_increment = M_PI / 180;
  s.range_max = 8.0;
  std::vector<float> ranges;
  castScan(grid, shapes, s, ranges);
  // asin(0.1 / 2) = 2.87 degrees: beams within +-2.87 degrees of 180 are hit.
  for (int i : {0, 1, 2, 357, 358, 359})
  {
    const double a = s.min_angle + i * s.angle_increment;
    EXPECT_NEAR(ranges[i], rayCircleRef(0, 0, std::cos(a), std::sin(a), c), 1e-6) << i;
    EXPECT_LT(ranges[i], 2.0f);
  }
  EXPECT_EQ(ranges[3], std::numeric_limits<float>::infinity());
  EXPECT_EQ(ranges[356], std::numeric_limits<float>::infinity());
}

TEST(CastScan, RandomScansMatchBruteForce)
{
  // Random grid, many random circles and boxes (some large and spanning buckets), small
  // buckets so that the bucket query matters; every beam of every scan must equal the
  // brute-force minimum over the grid reference and every shape's reference.
  const unsigned w = 160, h = 120;
  const double res = 0.05, ox = -4.0, oy = -3.0;
  std::mt19937 rng(3);
  std::vector<uint8_t> cells(w * h, 0);
  std::bernoulli_distribution sparse(0.004);
  for (auto& c : cells) c = sparse(rng) ? 1 : 0;
  for (unsigned x = 0; x < w; ++x) cells[x] = cells[(h - 1) * w + x] = 1;
  const GridRaycaster grid(cells, w, h, res, ox, oy);

  std::uniform_real_distribution<double> ux(-5.0, 5.0), uy(-4.0, 4.0), ua(-M_PI, M_PI);
  std::uniform_real_distribution<double> usize(0.05, 0.6);
  std::vector<Circle> circles;
  std::vector<OrientedBox> boxes;
  ShapeSet shapes(1.0);
  for (int k = 0; k < 60; ++k)
  {
    Circle c;
    c.x = ux(rng);
    c.y = uy(rng);
    c.radius = usize(rng);
    c.owner = k % 5;
    circles.push_back(c);
    shapes.addCircle(c);
  }
  for (int k = 0; k < 30; ++k)
  {
    OrientedBox b;
    b.x = ux(rng);
    b.y = uy(rng);
    b.yaw = ua(rng);
    b.half_length = usize(rng) * (k == 0 ? 4.0 : 1.0);  // one long box spans buckets
    b.half_width = usize(rng);
    b.owner = 10 + k % 3;
    boxes.push_back(b);
    shapes.addBox(b);
  }
  ASSERT_EQ(shapes.size(), 90u);

  int scans = 0, shape_hits = 0;
  std::vector<float> ranges;
  for (int trial = 0; trial < 200 && scans < 40; ++trial)
  {
    ScanSpec s;
    s.x = ux(rng);
    s.y = uy(rng);
    s.yaw = ua(rng);
    s.min_angle = -2.0;
    s.angle_increment = 4.0 / 179;
    s.beams = 180;
    s.range_min = 0.02;
    s.range_max = 6.0;
    s.ignore_owner = trial % 7 == 0 ? -1 : trial % 5;
    // Sensors inside a seen shape read all -Inf; checked elsewhere, skip those here.
    bool inside = false;
    for (const Circle& c : circles)
      if (c.owner != s.ignore_owner && std::hypot(c.x - s.x, c.y - s.y) <= c.radius) inside = true;
    for (const OrientedBox& b : boxes)
    {
      const double lx = std::cos(b.yaw) * (s.x - b.x) + std::sin(b.yaw) * (s.y - b.y);
      const double ly = -std::sin(b.yaw) * (s.x - b.x) + std::cos(b.yaw) * (s.y - b.y);
      if (std::abs(lx) <= b.half_length && std::abs(ly) <= b.half_width) inside = true;
    }
    if (inside || grid.occupiedAt(s.x, s.y)) continue;
    ++scans;
    castScan(grid, shapes, s, ranges);
    for (int i = 0; i < s.beams; ++i)
    {
      const double a = s.yaw + s.min_angle + i * s.angle_increment;
      const double cx = std::cos(a), cy = std::sin(a);
      double expected = bruteForceGridCast(cells, w, h, res, ox, oy, s.x, s.y, a, s.range_max);
      double shape = kInf;
      for (const Circle& c : circles)
        if (c.owner != s.ignore_owner || s.ignore_owner < 0) shape = std::min(shape, rayCircleRef(s.x, s.y, cx, cy, c));
      for (const OrientedBox& b : boxes)
        if (b.owner != s.ignore_owner || s.ignore_owner < 0)
          shape = std::min(shape, rayPolygon(s.x, s.y, cx, cy, boxCornersX(b), boxCornersY(b)));
      if (shape < expected)
      {
        expected = shape;
        ++shape_hits;
      }
      if (expected >= s.range_max)
        ASSERT_EQ(ranges[i], std::numeric_limits<float>::infinity()) << "scan " << scans << " beam " << i;
      else if (expected < s.range_min)
        ASSERT_EQ(ranges[i], -std::numeric_limits<float>::infinity()) << "scan " << scans << " beam " << i;
      else
        ASSERT_NEAR(ranges[i], expected, 1e-5) << "scan " << scans << " beam " << i;
    }
  }
  EXPECT_EQ(scans, 40);
  EXPECT_GT(shape_hits, 500);  // shapes really were hit, in front of walls
}

TEST(CastScan, RejectsBadSpec)
{
  const GridRaycaster grid = emptyGrid();
  std::vector<float> ranges;
  ScanSpec s = oneBeam(0, 0, 0, 0.0);
  EXPECT_THROW(castScan(grid, ShapeSet(), s, ranges), std::invalid_argument);
  s = oneBeam(0, 0, 0, 8.0);
  s.beams = -1;
  EXPECT_THROW(castScan(grid, ShapeSet(), s, ranges), std::invalid_argument);
  s.beams = 0;
  castScan(grid, ShapeSet(), s, ranges);
  EXPECT_TRUE(ranges.empty());
  s.beams = 10;
  s.yaw = std::nan("");
  EXPECT_THROW(castScan(grid, ShapeSet(), s, ranges), std::invalid_argument);
  ShapeSet shapes;
  Circle c;
  c.radius = -0.1;
  EXPECT_THROW(shapes.addCircle(c), std::invalid_argument);
  OrientedBox b;
  b.x = std::numeric_limits<double>::infinity();
  EXPECT_THROW(shapes.addBox(b), std::invalid_argument);
  EXPECT_EQ(shapes.size(), 0u);
}

// ---------------------------------------------------------------------------------------------
// Wall sweep (castScanWalls): whole scans against the wall faces, compared with the grid walk
// and the brute-force reference
// ---------------------------------------------------------------------------------------------
namespace
{
using mbot_sim::WallMethod;

/// A laser layout: n beams from first_angle, increment apart [rad].
struct Layout
{
  int n;
  double first_angle;
  double increment;
};

/// Cells of a map with random rectangular blocks (walls, furniture) and a few single cells.
std::vector<uint8_t> blockMap(unsigned w, unsigned h, std::mt19937& rng)
{
  std::vector<uint8_t> cells(static_cast<size_t>(w) * h, 0);
  std::uniform_int_distribution<unsigned> ux(0, w - 1), uy(0, h - 1), usize(1, 12);
  for (int k = 0; k < 25; ++k)
  {
    const unsigned x0 = ux(rng), y0 = uy(rng);
    const unsigned x1 = std::min(w, x0 + usize(rng)), y1 = std::min(h, y0 + usize(rng));
    for (unsigned y = y0; y < y1; ++y)
      for (unsigned x = x0; x < x1; ++x) cells[y * w + x] = 1;
  }
  return cells;
}

/// A cave: random noise smoothed by a few rounds of "occupied when most neighbours are".
std::vector<uint8_t> caveMap(unsigned w, unsigned h, std::mt19937& rng)
{
  std::vector<uint8_t> cells(static_cast<size_t>(w) * h, 0);
  std::bernoulli_distribution fill(0.42);
  for (auto& c : cells) c = fill(rng) ? 1 : 0;
  for (int round = 0; round < 3; ++round)
  {
    std::vector<uint8_t> next(cells.size());
    for (unsigned y = 0; y < h; ++y)
      for (unsigned x = 0; x < w; ++x)
      {
        int around = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
          {
            const int nx = static_cast<int>(x) + dx, ny = static_cast<int>(y) + dy;
            around +=
                nx < 0 || ny < 0 || nx >= static_cast<int>(w) || ny >= static_cast<int>(h) ? 1 : cells[ny * w + nx];
          }
        next[y * w + x] = around >= 5 ? 1 : 0;
      }
    cells.swap(next);
  }
  return cells;
}

/// Cast one scan with the given method; directions are cos/sin of the beam angles.
std::vector<double> castWalls(const GridRaycaster& grid, double x, double y, const Layout& l, double max_range,
                              WallMethod method, std::vector<double>* dx_out = nullptr,
                              std::vector<double>* dy_out = nullptr)
{
  std::vector<double> dx(l.n), dy(l.n), ranges(l.n, -1.0);
  for (int i = 0; i < l.n; ++i)
  {
    dx[i] = std::cos(l.first_angle + i * l.increment);
    dy[i] = std::sin(l.first_angle + i * l.increment);
  }
  grid.castScanWalls(x, y, dx.data(), dy.data(), l.first_angle, l.increment, l.n, max_range, ranges.data(), method);
  if (dx_out) *dx_out = dx;
  if (dy_out) *dy_out = dy;
  return ranges;
}

/// Random scans in random maps of one kind: the sweep must equal the brute-force reference
/// within 1e-9 m, and every method must agree with the grid walk within 1e-9 m.
template <typename MakeMap>
void checkRandomScans(MakeMap make_map, unsigned seed, int* swept_beams)
{
  const unsigned w = 64, h = 48;
  const double res = 0.05;
  std::mt19937 rng(seed);
  const std::vector<Layout> layouts = {
      {360, -M_PI, 2 * M_PI / 360},           // the usual full turn
      {720, -0.75 * M_PI, 1.5 * M_PI / 720},  // 270 degrees
      {1, 0.3, 0.0},                          // one beam
      {97, 1.0, -0.6 / 96},                   // a narrow fan turning clockwise
      {500, 2.0, 2.5 * M_PI / 499},           // more than a full turn
  };
  std::uniform_real_distribution<double> ux(0.0, w * res), uy(0.0, h * res);
  std::uniform_real_distribution<double> ua(-M_PI, M_PI), ur(0.1, 4.0);
  for (int map = 0; map < 4; ++map)
  {
    const std::vector<uint8_t> cells = make_map(w, h, rng);
    const GridRaycaster grid(cells, w, h, res, 0.0, 0.0);
    for (int scan = 0; scan < 10; ++scan)
    {
      double x = ux(rng), y = uy(rng);
      if (grid.occupiedAt(x, y)) continue;
      Layout l = layouts[scan % layouts.size()];
      l.first_angle += ua(rng);                                 // the sensor's yaw
      const double max_range = scan % 3 == 0 ? 10.0 : ur(rng);  // 10 m: leaves the grid
      std::vector<double> dx, dy;
      const std::vector<double> sweep = castWalls(grid, x, y, l, max_range, WallMethod::kSweep, &dx, &dy);
      const std::vector<double> walk = castWalls(grid, x, y, l, max_range, WallMethod::kGridWalk);
      const std::vector<double> automatic = castWalls(grid, x, y, l, max_range, WallMethod::kAuto);
      for (int i = 0; i < l.n; ++i)
      {
        const double expected = bruteForceGridCastDir(cells, w, h, res, x, y, dx[i], dy[i], max_range);
        ASSERT_NEAR(sweep[i], expected, 1e-9)
            << "map " << map << " scan " << scan << " beam " << i << " from (" << x << ", " << y << ")";
        ASSERT_NEAR(sweep[i], walk[i], 1e-9) << "map " << map << " scan " << scan << " beam " << i;
        ASSERT_NEAR(automatic[i], walk[i], 1e-9) << "map " << map << " scan " << scan;
      }
      *swept_beams += l.n;
    }
  }
}
}  // namespace

TEST(WallSweep, FacesAreMergedRunsOfCellEdges)
{
  // One 3 x 2 block in the open: 4 faces (one per side), however many cell edges.
  std::vector<Cell> block;
  for (int y = 5; y < 7; ++y)
    for (int x = 4; x < 7; ++x) block.push_back({x, y});
  EXPECT_EQ(makeGrid(12, 12, 0.1, 0.0, 0.0, block).wallFaceCount(), 4u);
  // A wall along the grid's edge: no face on the edge itself (outside is free, and a sensor
  // inside never sees it), one face towards the inside.
  std::vector<Cell> edge;
  for (int x = 0; x < 12; ++x) edge.push_back({x, 0});
  EXPECT_EQ(makeGrid(12, 12, 0.1, 0.0, 0.0, edge).wallFaceCount(), 1u);
  // A staircase: every step has its own faces.
  EXPECT_EQ(makeGrid(12, 12, 0.1, 0.0, 0.0, {{3, 3}, {4, 4}}).wallFaceCount(), 8u);
  EXPECT_EQ(makeGrid(12, 12, 0.1, 0.0, 0.0, {}).wallFaceCount(), 0u);
}

TEST(WallSweep, RandomBlockMapsMatchBruteForceAndTheWalk)
{
  int swept = 0;
  checkRandomScans(blockMap, 101, &swept);
  EXPECT_GT(swept, 5000);
}

TEST(WallSweep, RandomCaveMapsMatchBruteForceAndTheWalk)
{
  int swept = 0;
  checkRandomScans(caveMap, 202, &swept);
  EXPECT_GT(swept, 5000);
}

TEST(WallSweep, EdgeCasesMatchTheWalk)
{
  // The room of FanEdgeCases: 4 x 4 m, 0.1 m cells, one-cell walls all round, a wall cell at
  // (20, 10); and the same without the room's walls, where beams leave the grid.
  const double res = 0.1;
  std::vector<Cell> walls = {{20, 10}, {25, 25}, {26, 24}};
  for (int k = 0; k < 40; ++k)
  {
    walls.push_back({k, 0});
    walls.push_back({k, 39});
    walls.push_back({0, k});
    walls.push_back({39, k});
  }
  const GridRaycaster room = makeGrid(40, 40, res, 0.0, 0.0, walls);
  const GridRaycaster open_grid = makeGrid(40, 40, res, 0.0, 0.0, {{20, 10}, {25, 25}});
  const double d = std::sqrt(0.5);
  // Eight beams, 45 degrees apart, with exact zero components and exact diagonals.
  const double dx[8] = {1, d, 0, -d, -1, -d, 0, d};
  const double dy[8] = {0, d, 1, d, 0, -d, -1, -d};
  struct Case
  {
    double x, y, max_range;
    const char* what;
  };
  const std::vector<Case> cases = {
      {1.05, 1.05, 8.0, "cell centre: diagonals through cell corners"},
      {2.05, 2.05, 8.0, "diagonal passing the corner between (25, 25) and (26, 24)"},
      {2.0 - 1e-9, 1.05, 8.0, "1e-9 m left of the wall cell (20, 10)"},
      {2.1 + 1e-9, 1.05, 8.0, "1e-9 m right of it"},
      {2.05, 1.0 - 1e-9, 8.0, "1e-9 m below it"},
      {1.05, 1.05, 0.95, "max range exactly at a wall"},
      {1.05, 1.05, 0.95 - 1e-9, "max range just short of a wall"},
      {1.05, 1.05, 0.95 + 1e-9, "max range just past a wall"},
      {1.05, 1.0, 8.0, "on a grid line: beams along it graze the walls (walk used)"},
      {0.1 + 1e-12, 0.1 + 1e-12, 8.0, "a hair off the room's inner corner"},
      {2.0, 1.05, 8.0, "on the wall's face (walk used)"},
      {2.05, 1.05, 8.0, "inside a wall"},
      {-1.0, 1.05, 8.0, "outside the grid (walk used)"},
  };
  double got[8], want[8];
  for (const GridRaycaster* grid : {&room, &open_grid})
    for (const Case& c : cases)
      for (double first : {0.0, M_PI})  // the same beams listed from another start
      {
        const int shift = first == 0.0 ? 0 : 4;
        double sx[8], sy[8];
        for (int i = 0; i < 8; ++i)
        {
          sx[i] = dx[(i + shift) % 8];
          sy[i] = dy[(i + shift) % 8];
        }
        grid->castScanWalls(c.x, c.y, sx, sy, first, M_PI / 4, 8, c.max_range, got, WallMethod::kSweep);
        grid->castFan(c.x, c.y, sx, sy, 8, c.max_range, want);
        for (int i = 0; i < 8; ++i)
          ASSERT_NEAR(got[i], want[i], 1e-12) << c.what << ", beam " << i << ", open " << (grid == &open_grid);
      }
  // The analytic values in the room (as in FanEdgeCases).
  room.castScanWalls(1.05, 1.05, dx, dy, 0.0, M_PI / 4, 8, 8.0, got, WallMethod::kSweep);
  EXPECT_NEAR(got[0], 0.95, 1e-12);
  EXPECT_NEAR(got[1], 1.45 * std::sqrt(2.0), 1e-9);  // corner of (25, 25) at (2.5, 2.5)
  EXPECT_NEAR(got[5], 0.95 * std::sqrt(2.0), 1e-9);  // corner (0.1, 0.1)
  room.castScanWalls(2.0 - 1e-9, 1.05, dx, dy, 0.0, M_PI / 4, 8, 8.0, got, WallMethod::kSweep);
  EXPECT_NEAR(got[0], 1e-9, 1e-12);
  room.castScanWalls(1.05, 1.05, dx, dy, 0.0, M_PI / 4, 1, 0.95 - 1e-9, got, WallMethod::kSweep);
  EXPECT_EQ(got[0], 0.95 - 1e-9);
  open_grid.castScanWalls(1.05, 1.05, dx, dy, 0.0, M_PI / 4, 8, 8.0, got, WallMethod::kSweep);
  EXPECT_EQ(got[2], 8.0);  // leaves the grid
  EXPECT_EQ(got[4], 8.0);
  // A direction that is not finite is refused, whichever the method.
  const double bad_x[2] = {1.0, std::nan("")}, bad_y[2] = {0.0, 1.0};
  for (WallMethod m : {WallMethod::kAuto, WallMethod::kSweep, WallMethod::kGridWalk})
    EXPECT_THROW(room.castScanWalls(1.05, 1.05, bad_x, bad_y, 0.0, 1.0, 2, 8.0, got, m), std::invalid_argument);
}

TEST(WallSweep, ScansFromCellCentresAtDiagonalsMatchTheWalk)
{
  // Beams every 45 degrees from cell centres run exactly through cell corners, where the
  // walk's tie rule decides; the sweep must reproduce it in block and cave maps alike.
  const unsigned w = 50, h = 40;
  const double res = 0.05;
  std::mt19937 rng(9);
  const double d = std::sqrt(0.5);
  const double dx[8] = {1, d, 0, -d, -1, -d, 0, d};
  const double dy[8] = {0, d, 1, d, 0, -d, -1, -d};
  int compared = 0;
  for (int map = 0; map < 6; ++map)
  {
    const std::vector<uint8_t> cells = map % 2 ? caveMap(w, h, rng) : blockMap(w, h, rng);
    const GridRaycaster grid(cells, w, h, res, 0.0, 0.0);
    for (unsigned cy = 0; cy < h; cy += 3)
      for (unsigned cx = 0; cx < w; cx += 3)
      {
        if (cells[cy * w + cx]) continue;
        double got[8], want[8];
        const double x = (cx + 0.5) * res, y = (cy + 0.5) * res;
        grid.castScanWalls(x, y, dx, dy, 0.0, M_PI / 4, 8, 3.0, got, WallMethod::kSweep);
        grid.castFan(x, y, dx, dy, 8, 3.0, want);
        for (int i = 0; i < 8; ++i)
          ASSERT_NEAR(got[i], want[i], 1e-12) << "map " << map << " cell " << cx << ", " << cy << " beam " << i;
        compared += 8;
      }
  }
  EXPECT_GT(compared, 2000);
}

TEST(WallSweep, AnyMethodGivesTheSameScan)
{
  // kAuto picks the walk where many faces are in range (a cave) and the sweep in open rooms;
  // castScan's results must not depend on that choice. Also an offset origin.
  std::mt19937 rng(33);
  const unsigned w = 160, h = 120;
  const std::vector<uint8_t> cave = caveMap(w, h, rng);
  std::vector<uint8_t> room(static_cast<size_t>(w) * h, 0);
  for (unsigned x = 0; x < w; ++x) room[x] = room[(h - 1) * w + x] = 1;
  for (unsigned y = 0; y < h; ++y) room[y * w] = room[y * w + w - 1] = room[y * w + 80] = y < 90 ? 1 : 0;
  const Layout l{360, -M_PI, 2 * M_PI / 360};
  std::uniform_real_distribution<double> ux(-2.0, 6.0), uy(1.0, 7.0), ua(-M_PI, M_PI);
  for (const std::vector<uint8_t>* cells : {&cave, static_cast<const std::vector<uint8_t>*>(&room)})
  {
    const GridRaycaster grid(*cells, w, h, 0.05, -2.0, 1.0);
    int scans = 0;
    for (int k = 0; k < 200 && scans < 30; ++k)
    {
      const double x = ux(rng), y = uy(rng);
      if (grid.occupiedAt(x, y)) continue;
      ++scans;
      Layout yawed = l;
      yawed.first_angle += ua(rng);
      const std::vector<double> a = castWalls(grid, x, y, yawed, 8.0, WallMethod::kAuto);
      const std::vector<double> s = castWalls(grid, x, y, yawed, 8.0, WallMethod::kSweep);
      const std::vector<double> g = castWalls(grid, x, y, yawed, 8.0, WallMethod::kGridWalk);
      for (int i = 0; i < l.n; ++i)
      {
        ASSERT_NEAR(s[i], g[i], 1e-9) << "beam " << i;
        ASSERT_NEAR(a[i], g[i], 1e-9) << "beam " << i;
        // As castScan reports them (floats): identical.
        ASSERT_EQ(static_cast<float>(s[i]), static_cast<float>(g[i])) << "beam " << i;
      }
    }
    EXPECT_EQ(scans, 30);
  }
}
