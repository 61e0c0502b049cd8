/**
 * @file map_io.cpp
 * @brief map_server-compatible map loading: the yaml (strictly read) and a PGM image (P5 binary
 *        or P2 text), turned into occupancy values exactly as map_server's image_loader computes
 *        them (moved from mbot_sim's map_io.cpp, plus the scale and raw modes).
 */
#include "mbot_common/map_io.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>

namespace mbot_common
{
namespace
{
/// Reads the whitespace- and comment-separated header tokens of a PGM.
class PgmHeader
{
public:
  PgmHeader(const std::string& bytes, std::string path) : bytes_(bytes), path_(std::move(path)) {}

  std::string token()
  {
    skipSpaceAndComments();
    std::string out;
    while (pos_ < bytes_.size() && !std::isspace(static_cast<unsigned char>(bytes_[pos_])) && bytes_[pos_] != '#')
      out += bytes_[pos_++];
    return out;
  }

  unsigned positive(const std::string& what, unsigned max_value)
  {
    const std::string t = token();
    if (t.empty() || t.find_first_not_of("0123456789") != std::string::npos || t.size() > 9)
      throw MapError(path_ + ": bad PGM header: expected " + what + " (a positive integer), got \"" + t + "\"");
    const unsigned long v = std::stoul(t);
    if (v == 0 || v > max_value)
      throw MapError(path_ + ": bad PGM header: " + what + " must be in [1, " + std::to_string(max_value) + "], got " +
                     t);
    return static_cast<unsigned>(v);
  }

  /// After maxval exactly one whitespace byte separates the header from binary data.
  size_t binaryStart() const { return pos_ + 1; }

  void skipSpaceAndComments()
  {
    while (pos_ < bytes_.size())
    {
      if (bytes_[pos_] == '#')
        while (pos_ < bytes_.size() && bytes_[pos_] != '\n') ++pos_;
      else if (std::isspace(static_cast<unsigned char>(bytes_[pos_])))
        ++pos_;
      else
        break;
    }
  }

private:
  const std::string& bytes_;
  std::string path_;
  size_t pos_ = 0;
};

std::string directoryOf(const std::string& path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

}  // namespace

const char* mapModeName(MapMode mode)
{
  switch (mode)
  {
    case MapMode::SCALE: return "scale";
    case MapMode::RAW: return "raw";
    default: return "trinary";
  }
}

std::array<int, 2> OccupancyMap::worldToCell(double x, double y) const
{
  // the point in the grid's own frame (rotated by the origin's yaw)
  const double dx = x - origin_x, dy = y - origin_y;
  const double c = std::cos(origin_yaw), s = std::sin(origin_yaw);
  const double gx = c * dx + s * dy, gy = -s * dx + c * dy;
  return {static_cast<int>(std::floor(gx / resolution)), static_cast<int>(std::floor(gy / resolution))};
}

Point2D OccupancyMap::cellToWorld(int mx, int my) const
{
  const double gx = (mx + 0.5) * resolution, gy = (my + 0.5) * resolution;
  const double c = std::cos(origin_yaw), s = std::sin(origin_yaw);
  return Point2D{origin_x + c * gx - s * gy, origin_y + s * gx + c * gy};
}

int8_t occupancyValue(uint8_t grey, double occupied_thresh, double free_thresh, bool negate, MapMode mode)
{
  double color = grey;
  if (negate) color = 255.0 - color;
  // map_server keeps the value in an unsigned char and stores it in the int8 grid
  if (mode == MapMode::RAW) return static_cast<int8_t>(static_cast<uint8_t>(color));
  const double occ = (255.0 - color) / 255.0;
  if (occ > occupied_thresh) return 100;
  if (occ < free_thresh) return 0;
  if (mode == MapMode::TRINARY) return -1;
  const double span = occupied_thresh - free_thresh;
  const double ratio = span > 0.0 ? (occ - free_thresh) / span : 0.0;
  return static_cast<int8_t>(static_cast<uint8_t>(1.0 + 98.0 * ratio));
}

std::vector<uint8_t> readPgm(const std::string& path, unsigned& width, unsigned& height, const std::string& yaml_path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    if (!yaml_path.empty()) throw MapError(yaml_path + ": image: cannot read \"" + path + "\" (missing or unreadable)");
    throw MapError(path + ": cannot read the file (missing or unreadable)");
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  PgmHeader header(bytes, path);
  const std::string magic = header.token();
  if (magic != "P5" && magic != "P2")
    throw MapError(path + ": bad PGM header: expected magic P5 (binary) or P2 (text), got \"" + magic.substr(0, 8) +
                   "\"");
  width = header.positive("width", 1u << 16);
  height = header.positive("height", 1u << 16);
  const unsigned maxval = header.positive("maxval", 65535);
  const size_t count = static_cast<size_t>(width) * height;
  std::vector<uint8_t> pixels(count);

  auto scaled = [maxval](unsigned v) -> uint8_t {
    if (v > maxval) v = maxval;
    return static_cast<uint8_t>(maxval == 255 ? v : v * 255u / maxval);
  };

  if (magic == "P5")
  {
    const size_t bytes_per_pixel = maxval < 256 ? 1 : 2;  // 16-bit PGM is big-endian
    const size_t start = header.binaryStart();
    if (start > bytes.size() || bytes.size() - start < count * bytes_per_pixel)
      throw MapError(path + ": truncated PGM: expected " + std::to_string(count * bytes_per_pixel) +
                     " bytes of pixels for " + std::to_string(width) + "x" + std::to_string(height) + ", got " +
                     std::to_string(start > bytes.size() ? 0 : bytes.size() - start));
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + start);
    for (size_t i = 0; i < count; ++i)
      pixels[i] = bytes_per_pixel == 1 ? scaled(data[i]) : scaled(data[2 * i] * 256u + data[2 * i + 1]);
  }
  else
  {
    for (size_t i = 0; i < count; ++i)
    {
      const std::string t = header.token();
      if (t.empty())
        throw MapError(path + ": truncated PGM: expected " + std::to_string(count) + " pixel values, got " +
                       std::to_string(i));
      if (t.find_first_not_of("0123456789") != std::string::npos || t.size() > 6)
        throw MapError(path + ": bad PGM pixel " + std::to_string(i) + ": expected an integer, got \"" + t + "\"");
      pixels[i] = scaled(static_cast<unsigned>(std::stoul(t)));
    }
  }
  return pixels;
}

OccupancyMap loadMap(const std::string& yaml_path)
{
  const StrictYaml<MapError> reader(yaml_path);
  const YAML::Node root = reader.load();
  reader.checkKeys(root, "", {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode"},
                   {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate"});

  OccupancyMap map;
  map.yaml_path = yaml_path;
  map.resolution = reader.number(root["resolution"], "resolution", "a number > 0 [m/cell]");
  if (map.resolution <= 0.0) reader.expected("resolution", "a number > 0 [m/cell]", root["resolution"]);
  const std::vector<double> origin = reader.numbers(root["origin"], "origin", 3, "a list of 3 numbers [x, y, yaw]");
  map.origin_x = origin[0];
  map.origin_y = origin[1];
  map.origin_yaw = origin[2];

  map.occupied_thresh = reader.number(root["occupied_thresh"], "occupied_thresh", "a number in [0, 1]");
  if (map.occupied_thresh < 0.0 || map.occupied_thresh > 1.0)
    reader.expected("occupied_thresh", "a number in [0, 1]", root["occupied_thresh"]);
  map.free_thresh = reader.number(root["free_thresh"], "free_thresh", "a number in [0, 1]");
  if (map.free_thresh < 0.0 || map.free_thresh > 1.0)
    reader.expected("free_thresh", "a number in [0, 1]", root["free_thresh"]);
  if (map.free_thresh > map.occupied_thresh)
    reader.expected("free_thresh", "a number <= occupied_thresh", root["free_thresh"]);

  // map_server reads negate as an integer (0 or 1); true/false are accepted as well.
  const YAML::Node negate = root["negate"];
  const bool plain = negate.IsScalar() && negate.Tag() != "!";
  bool as_bool = false;
  if (plain && (negate.Scalar() == "0" || negate.Scalar() == "1"))
    map.negate = negate.Scalar() == "1";
  else if (plain && YAML::convert<bool>::decode(negate, as_bool))
    map.negate = as_bool;
  else
    reader.expected("negate", "0 or 1", negate);

  if (root["mode"])
  {
    const std::string mode = reader.text(root["mode"], "mode", "trinary, scale or raw");
    if (mode == "trinary")
      map.mode = MapMode::TRINARY;
    else if (mode == "scale")
      map.mode = MapMode::SCALE;
    else if (mode == "raw")
      map.mode = MapMode::RAW;
    else
      reader.expected("mode", "trinary, scale or raw", root["mode"]);
  }

  const std::string image = reader.text(root["image"], "image", "an image file name");
  if (image.empty()) reader.expected("image", "an image file name", root["image"]);
  map.image_path = image[0] == '/' ? image : directoryOf(yaml_path) + "/" + image;
  const std::vector<uint8_t> pixels = readPgm(map.image_path, map.width, map.height, yaml_path);

  map.data.assign(static_cast<size_t>(map.width) * map.height, -1);
  for (unsigned j = 0; j < map.height; ++j)  // j: image row, top first
    for (unsigned i = 0; i < map.width; ++i)
      // Flip: image row 0 is the top, map row 0 is the bottom (at origin_y).
      map.data[static_cast<size_t>(map.height - j - 1) * map.width + i] = occupancyValue(
          pixels[static_cast<size_t>(j) * map.width + i], map.occupied_thresh, map.free_thresh, map.negate, map.mode);
  return map;
}

}  // namespace mbot_common
