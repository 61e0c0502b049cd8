/**
 * @file map_io.cpp
 * @brief map_server-compatible map loading: the yaml (strictly read) and a PGM image (P5 binary
 *        or P2 text), turned into trinary occupancy values exactly as map_server's image_loader
 *        computes them.
 */
#include "mbot_sim/map_io.h"

#include "mbot_sim/strict_yaml.h"

#include <cctype>
#include <fstream>
#include <iterator>
#include <sstream>

namespace mbot_sim
{
namespace
{
/// A grey image as read from the file, top row first; values scaled to 0..255 as SDL_image
/// (which map_server uses) scales them for maxval != 255.
struct GreyImage
{
  unsigned width = 0;
  unsigned height = 0;
  std::vector<uint8_t> pixels;
};

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
      throw MapError(path_ + ": bad PGM header: " + what + " must be in [1, " + std::to_string(max_value) +
                     "], got " + t);
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

GreyImage readPgm(const std::string& path, const std::string& yaml_path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MapError(yaml_path + ": image: cannot read \"" + path + "\" (missing or unreadable)");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  PgmHeader header(bytes, path);
  const std::string magic = header.token();
  if (magic != "P5" && magic != "P2")
    throw MapError(path + ": bad PGM header: expected magic P5 (binary) or P2 (text), got \"" +
                   magic.substr(0, 8) + "\"");
  GreyImage image;
  image.width = header.positive("width", 1u << 16);
  image.height = header.positive("height", 1u << 16);
  const unsigned maxval = header.positive("maxval", 65535);
  const size_t count = static_cast<size_t>(image.width) * image.height;
  image.pixels.resize(count);

  auto scaled = [maxval](unsigned v) -> uint8_t {
    if (v > maxval) v = maxval;
    return static_cast<uint8_t>(maxval == 255 ? v : v * 255u / maxval);
  };

  if (magic == "P5")
  {
    const size_t bytes_per_pixel = maxval < 256 ? 1 : 2;
    const size_t start = header.binaryStart();
    if (start > bytes.size() || bytes.size() - start < count * bytes_per_pixel)
      throw MapError(path + ": truncated PGM: expected " + std::to_string(count * bytes_per_pixel) +
                     " bytes of pixels for " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                     ", got " + std::to_string(start > bytes.size() ? 0 : bytes.size() - start));
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + start);
    for (size_t i = 0; i < count; ++i)
      image.pixels[i] = bytes_per_pixel == 1 ? scaled(data[i]) : scaled(data[2 * i] * 256u + data[2 * i + 1]);
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
      image.pixels[i] = scaled(static_cast<unsigned>(std::stoul(t)));
    }
  }
  return image;
}

std::string directoryOf(const std::string& path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

}  // namespace

OccupancyMap loadMap(const std::string& yaml_path)
{
  const StrictYaml<MapError> reader(yaml_path);
  const YAML::Node root = reader.load();
  reader.checkKeys(root, "", {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode"},
                   {"image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate"});

  OccupancyMap map;
  map.resolution = reader.number(root["resolution"], "resolution", "a number > 0 [m/cell]");
  if (map.resolution <= 0.0) reader.expected("resolution", "a number > 0 [m/cell]", root["resolution"]);
  const std::vector<double> origin =
      reader.numbers(root["origin"], "origin", 3, "a list of 3 numbers [x, y, yaw]");
  map.origin_x = origin[0];
  map.origin_y = origin[1];
  map.origin_yaw = origin[2];

  const double occupied_thresh = reader.number(root["occupied_thresh"], "occupied_thresh", "a number in [0, 1]");
  const double free_thresh = reader.number(root["free_thresh"], "free_thresh", "a number in [0, 1]");
  if (occupied_thresh < 0.0 || occupied_thresh > 1.0)
    reader.expected("occupied_thresh", "a number in [0, 1]", root["occupied_thresh"]);
  if (free_thresh < 0.0 || free_thresh > 1.0) reader.expected("free_thresh", "a number in [0, 1]", root["free_thresh"]);
  if (free_thresh > occupied_thresh)
    reader.expected("free_thresh", "a number <= occupied_thresh", root["free_thresh"]);

  // map_server reads negate as an integer (0 or 1); accept true/false as well.
  const YAML::Node negate_node = root["negate"];
  bool negate = false;
  if (negate_node.IsScalar() && (negate_node.Scalar() == "0" || negate_node.Scalar() == "1"))
    negate = negate_node.Scalar() == "1";
  else if (negate_node.IsScalar() && (negate_node.Scalar() == "true" || negate_node.Scalar() == "false"))
    negate = negate_node.Scalar() == "true";
  else
    reader.expected("negate", "0 or 1", negate_node);

  if (root["mode"])
  {
    const std::string mode = reader.text(root["mode"], "mode");
    if (mode != "trinary")
      reader.expected("mode", "trinary (the only mode stage_node and the map server support)", root["mode"]);
  }

  std::string image_path = reader.text(root["image"], "image", "an image file name");
  if (image_path.empty()) reader.expected("image", "an image file name", root["image"]);
  if (image_path[0] != '/') image_path = directoryOf(yaml_path) + "/" + image_path;
  const GreyImage image = readPgm(image_path, yaml_path);

  map.width = image.width;
  map.height = image.height;
  map.data.assign(static_cast<size_t>(map.width) * map.height, -1);
  for (unsigned j = 0; j < image.height; ++j)  // j: image row, top first
  {
    for (unsigned i = 0; i < image.width; ++i)
    {
      // As map_server's image_loader.cpp: occupancy probability from the (negated) grey value.
      double color = image.pixels[static_cast<size_t>(j) * image.width + i];
      if (negate) color = 255.0 - color;
      const double occ = (255.0 - color) / 255.0;
      int8_t value = -1;
      if (occ > occupied_thresh)
        value = 100;
      else if (occ < free_thresh)
        value = 0;
      // Flip: image row 0 is the top, map row 0 is the bottom (at origin_y).
      map.data[static_cast<size_t>(map.height - j - 1) * map.width + i] = value;
    }
  }
  return map;
}

}  // namespace mbot_sim
