/**
 * @file build_world.cpp
 * @brief From a world file's structs to a World: buildWorld() (map, obstacles, moving obstacles,
 *        robots, faults, with errors naming the file and the key), the map's occupied cells
 *        merged into wall rectangles, and a run-time obstacle request checked into an
 *        ObstacleConfig. See world.h.
 */
#include "mbot_sim/world.h"

namespace mbot_sim
{
using mbot_description::RobotModel;

std::vector<CellRect> mergeOccupiedCells(const OccupancyMap& map)
{
  std::vector<CellRect> rects;
  std::vector<uint8_t> taken(map.data.size(), 0);
  auto free_cell = [&](unsigned x, unsigned y) {
    const size_t i = static_cast<size_t>(y) * map.width + x;
    return map.data[i] == 100 && !taken[i];
  };
  for (unsigned y = 0; y < map.height; ++y)
  {
    for (unsigned x = 0; x < map.width; ++x)
    {
      if (!free_cell(x, y)) continue;
      CellRect r{x, y, 0, 1};
      while (x + r.width < map.width && free_cell(x + r.width, y)) ++r.width;
      while (y + r.height < map.height)
      {
        bool whole_run = true;
        for (unsigned k = 0; k < r.width && whole_run; ++k) whole_run = free_cell(x + k, y + r.height);
        if (!whole_run) break;
        ++r.height;
      }
      for (unsigned yy = y; yy < y + r.height; ++yy)
        for (unsigned xx = x; xx < x + r.width; ++xx) taken[static_cast<size_t>(yy) * map.width + xx] = 1;
      rects.push_back(r);
    }
  }
  return rects;
}

ObstacleConfig obstacleFromRequest(const std::string& name, const std::string& shape, double length, double width,
                                   double radius, const Pose2D& pose)
{
  ObstacleConfig o;
  o.name = name;
  o.pose = pose;
  // The world file reader's words: a box has a size, a cylinder a radius, and not the other.
  if (shape == "box")
  {
    if (radius != 0.0) throw SimError("obstacle " + name + ": radius: a box has a size [length, width], not a radius");
    o.shape.type = ShapeConfig::Type::BOX;
    o.shape.length = length;
    o.shape.width = width;
  }
  else if (shape == "cylinder")
  {
    if (length != 0.0 || width != 0.0)
      throw SimError("obstacle " + name + ": length, width: a cylinder has a radius, not a size");
    o.shape.type = ShapeConfig::Type::CYLINDER;
    o.shape.radius = radius;
  }
  else
  {
    throw SimError("obstacle " + name + ": shape: expected box or cylinder, got \"" + shape + "\"");
  }
  return o;
}

std::unique_ptr<World> buildWorld(const WorldConfig& config, const ModelLoader& load_model, double watchdog_timeout)
{
  auto fail = [&](const std::string& key, const std::string& problem) -> WorldConfigError {
    return WorldConfigError(config.file + ": " + key + ": " + problem);
  };
  WorldSettings settings;
  settings.physics_step = config.physics_step;
  settings.seed = config.seed;
  settings.noise = config.noise;
  settings.wall_height = config.wall_height;
  settings.watchdog_timeout = watchdog_timeout;
  std::unique_ptr<World> world;
  try
  {
    world = std::make_unique<World>(config.map_data, settings);
  }
  catch (const SimError& e)
  {
    throw fail("map", e.what());
  }

  for (const auto& o : config.obstacles)
  {
    try
    {
      world->addObstacle(o);
    }
    catch (const SimError& e)
    {
      throw fail(o.key, e.what());
    }
  }
  for (const auto& m : config.moving_obstacles)
  {
    try
    {
      world->addMovingObstacle(m);
    }
    catch (const SimError& e)
    {
      throw fail(m.key, e.what());
    }
  }
  for (const auto& r : config.robots)
  {
    RobotModel model;
    try
    {
      model = load_model(r.model);
    }
    catch (const std::exception& e)
    {
      throw fail(r.key + ".model", "cannot load model \"" + r.model + "\": " + e.what());
    }
    try
    {
      world->addRobot(r.name, model, r.pose);
    }
    catch (const SimError& e)
    {
      throw fail(r.key + ".pose", e.what());
    }
    if (r.lidar.enabled)
    {
      try
      {
        world->setLidar(world->findRobot(r.name), r.lidar);
      }
      catch (const SimError& e)
      {
        throw fail(r.key + ".lidar", e.what());
      }
    }
  }
  for (const auto& f : config.faults)
  {
    try
    {
      world->setFaults(f.robot, f.faults);
    }
    catch (const SimError& e)
    {
      throw fail(f.key, e.what());
    }
  }
  return world;
}

}  // namespace mbot_sim
