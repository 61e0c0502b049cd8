/**
 * @file lidar3d.h
 * @brief A 3D lidar in a 2.5D world (no ROS types): the map's walls extruded to one height, the
 *        floor plane z = 0, and upright prisms (boxes, cylinders: obstacles, people, robots)
 *        standing on the floor, each with its own height. The scan pattern is a model of a
 *        Livox Mid-360 (360 deg horizontal, -7..52 deg vertical, non-repetitive rosette).
 *
 * How a ray is cast (lidar3d.cpp): a ray with elevation e from height z0 first finds its
 * horizontal hit distance d against the walls with the 2D caster (GridRaycaster). It hits the
 * wall when its height z0 + d tan(e) at d is within [0, wall_height]; above, it passes over the
 * walls (an upward ray never comes down again); below 0 it met the floor first, at
 * d_floor = z0 / tan(-e). Prisms are cut exactly: the horizontal interval inside the footprint
 * intersected with the interval where the ray's height is within [0, height] (so a ray can pass
 * above a low box and hit the wall behind it, or land on the box's top). An upward ray that
 * clears everything gives no point, as a real lidar.
 */
#pragma once

#include "mbot_sim/raycast.h"

#include <cstdint>
#include <random>
#include <vector>

namespace mbot_sim
{
/// @brief An upright prism standing on the floor: a circle (radius) or a box (half sizes, yaw).
struct Prism
{
  bool is_box = false;
  double x = 0.0;  ///< centre [m]
  double y = 0.0;
  double yaw = 0.0;          ///< box orientation [rad]
  double radius = 0.0;       ///< circle [m]
  double half_length = 0.0;  ///< box, along its x [m]
  double half_width = 0.0;   ///< box, along its y [m]
  double height = 1.0;       ///< top above the floor [m]
  int owner = -1;            ///< a robot's lidar does not see its own body
  float intensity = 100.0f;  ///< what its points report (see Surface)
};

/// @brief What a point hit; the intensities are fixed per surface (a model, not reflectivity).
enum class Surface : uint8_t
{
  kNone = 0,
  kWall = 1,
  kFloor = 2,
  kPrism = 3,
};

/// @brief The 2.5D world a lidar sees: the walls (not owned, must outlive the scene) and prisms.
class Scene25D
{
public:
  /// @throws std::invalid_argument for wall_height <= 0
  Scene25D(const GridRaycaster* walls, double wall_height);
  void clearPrisms() { prisms_.clear(); }
  /// @throws std::invalid_argument for a non-finite pose, negative size or height <= 0
  void addPrism(const Prism& p);
  const std::vector<Prism>& prisms() const { return prisms_; }
  double wallHeight() const { return wall_height_; }
  const GridRaycaster& walls() const { return *walls_; }

private:
  const GridRaycaster* walls_;
  double wall_height_;
  std::vector<Prism> prisms_;
};

/// @brief The prisms near one sensor position, with their rotation precomputed; cheap to build
///        once per physics step per lidar, then used for every ray of that step.
class PrismQuery
{
public:
  /// Keep the prisms whose footprint comes within `reach` [m] of (x, y), except `ignore_owner`'s.
  void prepare(const Scene25D& scene, double x, double y, double reach, int ignore_owner);

  struct Near
  {
    Prism p;
    double cos_yaw = 1.0;
    double sin_yaw = 0.0;
  };
  const std::vector<Near>& near() const { return near_; }

private:
  std::vector<Near> near_;
};

/// @brief One ray's result: the distance along the ray [m] (+Inf: no return within max_range)
///        and the surface it hit.
struct RayHit
{
  double range = 0.0;
  Surface surface = Surface::kNone;
  float intensity = 0.0f;
};

/// @brief Cast one ray from (x, y, z) [m] (0 < z < wall height) along the horizontal unit vector
///        (dir_x, dir_y) with elevation `elevation` [rad] (|elevation| < pi/2) against the walls,
///        the floor and the prisms of `near` (prepared for this origin). No return within
///        max_range: range = +Inf, surface kNone.
RayHit castRay3D(const Scene25D& scene, const PrismQuery& near, double x, double y, double z, double dir_x,
                 double dir_y, double elevation, double max_range);

/// @brief As castRay3D() with the elevation given as its cosine and tangent (no trigonometry
///        per ray: the scanner has them from its pattern).
RayHit castRay3DTrig(const Scene25D& scene, const PrismQuery& near, double x, double y, double z, double dir_x,
                     double dir_y, double cos_e, double tan_e, double max_range);

/// @brief The same by brute force (small steps along the ray, `step` [m]): for tests only.
RayHit castRay3DBruteForce(const Scene25D& scene, double x, double y, double z, double dir_x, double dir_y,
                           double elevation, double max_range, double step, int ignore_owner);

/// @brief Settings of a lidar (world file `lidar:` of a robot; WORLD_FORMAT.md).
struct LidarSpec
{
  double rate = 10.0;               ///< frames per second [Hz]
  int points_per_frame = 20000;     ///< pattern points per frame (returns may be fewer)
  double min_elevation = -0.12217;  ///< [rad] (-7 deg)
  double max_elevation = 0.90757;   ///< [rad] (52 deg)
  double range_min = 0.1;           ///< [m] closer returns are dropped
  double range_max = 40.0;          ///< [m] farther returns are dropped
  double range_noise = 0.0;         ///< [m] Gaussian standard deviation on each range
  double range_quantization = 0.0;  ///< [m] ranges are rounded to multiples of this (0: not)
};

/// @brief The non-repetitive scan pattern (a model of the Mid-360's, not Livox's exact one).
///        Point n of the lidar's life (t = n / (rate * points_per_frame)) belongs to channel
///        j = n mod 4 (four interleaved petal sets) and points along
///          azimuth   a = 2 pi (rate t + j / 4) + (R / 2) (cos(w1 t + p_j) + cos(w2 t + p_j))
///          elevation e = e_c + (R / 2) (sin(w1 t + p_j) - sin(w2 t + p_j))
///        with e_c, R the centre and half of the vertical field, p_j = 2 pi g j, g = 0.618... (the
///        golden ratio's fraction), w1 = 2 pi rate 123.607, w2 = 2 pi rate 76.393 (w2 / w1 = g):
///        the head turns once per frame and two counter-rotating phasors (a Risley-prism rosette)
///        sweep petals over the vertical field. w1 / rate is irrational, so no frame repeats
///        another and the covered part of the field grows with integration time.
class LidarPattern
{
public:
  /// @throws std::invalid_argument for a spec out of range (rate, points <= 0, bad field)
  explicit LidarPattern(const LidarSpec& spec);
  /// Azimuth [rad, in the lidar frame, any multiple of 2 pi] and elevation [rad] of point n.
  void direction(uint64_t n, double& azimuth, double& elevation) const;

  /// @brief Walks the pattern point by point without trigonometry: the rotations are unit
  ///        complex numbers turned by a fixed step per point (exact again at every seek()).
  struct Cursor
  {
    uint64_t n = 0;
    double c1 = 1.0, s1 = 0.0;  ///< e^{i w1 t}
    double c2 = 1.0, s2 = 0.0;  ///< e^{i w2 t}
    double ch = 1.0, sh = 0.0;  ///< e^{i 2 pi rate t} (the head)
  };
  void seek(uint64_t n, Cursor& c) const;
  void next(Cursor& c) const;
  /// cos and sin of the azimuth and of the elevation of the cursor's point (as direction()).
  void unitDirection(const Cursor& c, double& cos_az, double& sin_az, double& cos_el, double& sin_el) const;

private:
  LidarSpec spec_;
  double dt_;  ///< time between points [s]
  double w1_;  ///< rosette rotation rates [rad/s]
  double w2_;
  double e_mid_;                                                      ///< centre of the vertical field [rad]
  double e_half_;                                                     ///< half the vertical field [rad]
  double step1_c_, step1_s_, step2_c_, step2_s_, steph_c_, steph_s_;  ///< per-point rotations
  double phase_c_[4], phase_s_[4];                                    ///< e^{i p_j} of the four channels
  double cos_mid_, sin_mid_;                                          ///< of e_mid_
};

/// @brief One point: position in the lidar frame at its own time [m], intensity, and its time
///        [s] after the frame's stamp. Laid out as the PointCloud2's points (20 bytes).
struct LidarPoint
{
  float x;
  float y;
  float z;
  float intensity;
  float time;
};

/// @brief A finished frame: stamp = sim time of its first pattern point.
struct LidarFrame
{
  double stamp = 0.0;
  std::vector<LidarPoint> points;
};

/// @brief A planar pose [m, rad] (the robot on the floor), for LidarScanner.
struct PlanarPose
{
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

/// @brief One lidar over time: casts each pattern point when sim time passes it, from the sensor
///        pose at that time (interpolated over the physics step), and completes frames.
class LidarScanner
{
public:
  /// @param mount_x, mount_y, mount_z, mount_yaw the lidar frame in the robot's base frame
  /// @param start sim time of the first frame [s]
  LidarScanner(const LidarSpec& spec, double mount_x, double mount_y, double mount_z, double mount_yaw, double start);

  /// Cast the points whose time lies in [t0, t1), the robot moving from `p0` (at t0) to `p1`
  /// (at t1). `near` must hold the prisms around the robot (reach: range_max plus the motion).
  /// Finished frames are appended to `done` (in order). `rng`: the robot's noise stream.
  /// @return the number of rays cast
  size_t advance(const Scene25D& scene, const PrismQuery& near, double t0, const PlanarPose& p0, double t1,
                 const PlanarPose& p1, std::mt19937& rng, std::vector<LidarFrame>& done);

  /// Drop the frame in progress; the next starts on the first frame boundary (start + k / rate)
  /// at or after `t` (after a teleport, a reset, or while nobody listens).
  void restart(double t);

  const LidarSpec& spec() const { return spec_; }
  double mountZ() const { return mount_z_; }

private:
  LidarSpec spec_;
  LidarPattern pattern_;
  double mount_x_, mount_y_, mount_z_, mount_yaw_;
  double start_;         ///< [s] the first frame's start: frames begin at start_ + k / rate
  double frame_start_;   ///< [s]
  uint64_t next_point_;  ///< global pattern index of the next point to cast
  int in_frame_ = 0;     ///< pattern points of the current frame already cast
  LidarFrame frame_;
  std::normal_distribution<double> gauss_{0.0, 1.0};
};

}  // namespace mbot_sim
