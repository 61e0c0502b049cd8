/**
 * @file sweep.h
 * @brief Drawing a moving body's predicted sweep into a costmap: shared by the robots layer
 *        (teammates, from what they report) and the moving obstacles layer (people and other
 *        unmapped things that move, from the laser).
 *
 * A sweep is the discs a body is predicted to cover over the next `prediction_time` seconds at a
 * constant twist, each grown by this robot's radius (where our centre would touch the body),
 * drawn with `prediction_cost`: high, but below INSCRIBED, so the planners prefer to pass behind
 * the body yet are never blocked by a guess.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/layer.h"

namespace mbot_navigation
{
/// @brief How far ahead a sweep is predicted and what it costs.
struct SweepPrediction
{
  double prediction_time = 1.0;   ///< how far ahead the motion is marked [s]
  double prediction_step = 0.1;   ///< time step of that prediction [s]
  uint8_t prediction_cost = 200;  ///< cost of the predicted sweep [0..252]; < INSCRIBED: passable
};

/// @brief Throw std::invalid_argument naming the key when `p` is out of range; `who` starts the text.
void checkSweepPrediction(const SweepPrediction& p, const std::string& who);

/**
 * @brief The poses from `start` to `p.prediction_time` ahead, every `p.prediction_step`, at a
 *        constant body twist (vx, vy [m/s] in the body frame of `start`, wz [rad/s]).
 *        The first pose is `start` itself.
 */
std::vector<Pose2D> predictPoses(const Pose2D& start, double vx, double vy, double wz, const SweepPrediction& p);

/// @brief Grow `bounds` by discs of `radius` [m] at every pose.
void includeDiscs(const std::vector<Pose2D>& poses, double radius, Bounds& bounds);

/// @brief Raise the cells of `window` whose centre is within `radius` [m] of (x, y) [m] to `c`
///        (by maximum); a disc smaller than a cell still raises the cell under its centre.
void drawDisc(Costmap2D& master, const CellWindow& window, double x, double y, double radius, uint8_t c);

/// @brief Draw discs of `radius` [m] at poses[1..] (the predicted ones) with `c`.
void drawSweep(Costmap2D& master, const CellWindow& window, const std::vector<Pose2D>& poses, double radius, uint8_t c);

}  // namespace mbot_navigation
