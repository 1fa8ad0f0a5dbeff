#include "shard_files.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

namespace shard_files {

namespace {

using nlohmann::json;
using hemilight::bake_pass_state;
using hemilight::bake_shard_result;

constexpr int row_samples = 1024;  // samples per row of a shard's EXR


std::uint64_t parse_key(const std::string& text, const std::string& file) {
  if (text.size() != 16 || text.find_first_not_of("0123456789abcdef") != std::string::npos)
    throw std::runtime_error(file + ": \"key\" is not 16 hex digits");
  return std::stoull(text, nullptr, 16);
}

// Writes `path` through a temporary file in the same directory renamed over it when complete.
template <class Write>
void write_atomically(const std::string& path, Write&& write) {
  const std::string tmp = path + ".tmp";
  try {
    write(tmp);
    std::filesystem::rename(tmp, path);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error("cannot write '" + path + "': " + e.what());
  }
}

void write_json(const std::string& path, const json& j) {
  write_atomically(path, [&](const std::string& tmp) {
    std::ofstream f(tmp);
    f << j.dump(2) << "\n";
    f.close();
    if (!f) throw std::runtime_error("write failed");
  });
}

json read_json(const std::string& path, const char* format) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read '" + path + "': no such file (or not readable)");
  json j;
  try {
    j = json::parse(f);
  } catch (const json::exception& e) {
    throw std::runtime_error("'" + path + "' is not valid JSON: " + e.what());
  }
  if (!j.is_object() || j.value("format", "") != format || j.value("version", 0) != 1)
    throw std::runtime_error("'" + path + "' is not a " + format + " manifest of version 1");
  return j;
}

// A field of a manifest, its type checked.
template <class T>
T field(const json& j, const char* name, const std::string& path) {
  if (!j.contains(name)) throw std::runtime_error("'" + path + "' has no \"" + name + "\"");
  try {
    return j.at(name).get<T>();
  } catch (const json::exception&) {
    throw std::runtime_error("'" + path + "': \"" + name + "\" has the wrong type");
  }
}

// Float planes of one size as a scanline EXR (ZIP), one FLOAT channel per name.
void write_planes(const std::string& path, int width, int height, const std::vector<std::string>& names,
                  const std::vector<std::vector<float>>& planes) {
  write_atomically(path, [&](const std::string& tmp) {
    Imf::Header header(width, height);
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < names.size(); ++c) {
      header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(planes[c].data())), sizeof(float),
                                     sizeof(float) * std::size_t(width)));
    }
    Imf::OutputFile out(tmp.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(height);
  });
}

// The named FLOAT planes of an EXR of the given size; throws naming the file.
std::vector<std::vector<float>> read_planes(const std::string& path, int width, int height, const std::vector<std::string>& names) {
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error("cannot read '" + path + "': no such file");
  std::vector<std::vector<float>> planes;
  try {
    // The header first: the manifest's size is believed only when the file agrees, before
    // anything is allocated for the pixels.
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    if (dw.min.x != 0 || dw.min.y != 0 || dw.max.x + 1 != width || dw.max.y + 1 != height)
      throw std::runtime_error("it is " + std::to_string(dw.max.x - dw.min.x + 1) + " x " + std::to_string(dw.max.y - dw.min.y + 1) +
                               ", its manifest says " + std::to_string(width) + " x " + std::to_string(height));
    planes.assign(names.size(), std::vector<float>(std::size_t(width) * std::size_t(height)));
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < names.size(); ++c) {
      const Imf::Channel* ch = in.header().channels().findChannel(names[c]);
      if (!ch || ch->type != Imf::FLOAT) throw std::runtime_error("it has no FLOAT channel " + names[c]);
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes[c].data()), sizeof(float), sizeof(float) * std::size_t(width)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(0, height - 1);
  } catch (const std::exception& e) {
    throw std::runtime_error("cannot read '" + path + "': " + e.what());
  }
  return planes;
}

std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

}  // namespace

std::string key_text(std::uint64_t key) {
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(key));
  return text;
}

std::string shard_stem(const std::string& prefix, int pass, int shard, int shards) {
  return prefix + "_pass" + std::to_string(pass) + "_shard" + std::to_string(shard) + "of" + std::to_string(shards);
}

std::string state_stem(const std::string& prefix, int pass) { return prefix + "_pass" + std::to_string(pass); }

void write_shard(const std::string& stem, const std::string& name, const bake_shard_result& r) {
  const std::size_t n = r.sample_count, ch = r.channel_names.size();
  const int width = int(std::clamp<std::size_t>(n, 1, row_samples));
  const int height = int(std::max<std::size_t>(1, (n + row_samples - 1) / row_samples));
  std::vector<std::vector<float>> planes(ch, std::vector<float>(std::size_t(width) * std::size_t(height), 0.0f));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < ch; ++c) planes[c][i] = r.values[i * ch + c];
  write_planes(stem + ".exr", width, height, r.channel_names, planes);
  const json j = {{"format", "hemilight_shard"}, {"version", 1}, {"name", name}, {"pass", r.pass}, {"shard", r.shard},
                  {"shards", r.shard_count}, {"key", key_text(r.key)}, {"samples", n}, {"width", width}, {"height", height},
                  {"channels", r.channel_names}, {"hemicubes", r.hemicubes}, {"records", r.records},
                  {"invalid_samples", r.invalid_samples}, {"seconds", r.seconds}, {"direct_seconds", r.direct_seconds},
                  {"values", file_name(stem + ".exr")}};
  write_json(stem + ".json", j);
}

bake_shard_result read_shard(const std::string& stem) {
  const std::string path = stem + ".json";
  const json j = read_json(path, "hemilight_shard");
  bake_shard_result r;
  r.pass = field<int>(j, "pass", path);
  r.shard = field<int>(j, "shard", path);
  r.shard_count = field<int>(j, "shards", path);
  r.key = parse_key(field<std::string>(j, "key", path), path);
  r.sample_count = field<std::size_t>(j, "samples", path);
  r.channel_names = field<std::vector<std::string>>(j, "channels", path);
  r.hemicubes = field<std::size_t>(j, "hemicubes", path);
  r.records = field<std::size_t>(j, "records", path);
  r.invalid_samples = field<std::size_t>(j, "invalid_samples", path);
  r.seconds = field<double>(j, "seconds", path);
  r.direct_seconds = field<double>(j, "direct_seconds", path);
  const int width = field<int>(j, "width", path), height = field<int>(j, "height", path);
  if (width < 1 || height < 1 || std::size_t(width) * std::size_t(height) > hemilight::max_image_pixels ||
      std::size_t(width) * std::size_t(height) < r.sample_count || r.channel_names.empty() ||
      r.channel_names.size() * std::size_t(width) * std::size_t(height) > (std::size_t(1) << 30))  // 4 GiB of values at most
    throw std::runtime_error("'" + path + "': width, height, samples and channels do not fit together");
  const std::vector<std::vector<float>> planes = read_planes(stem + ".exr", width, height, r.channel_names);
  const std::size_t ch = r.channel_names.size();
  r.values.resize(r.sample_count * ch);
  for (std::size_t i = 0; i < r.sample_count; ++i)
    for (std::size_t c = 0; c < ch; ++c) r.values[i * ch + c] = planes[c][i];
  return r;
}

void write_state(const std::string& stem, const std::string& name, const bake_pass_state& s) {
  const std::size_t texels = std::size_t(s.radiance.width) * std::size_t(s.radiance.height);
  std::vector<std::vector<float>> planes(4, std::vector<float>(texels));
  for (std::size_t k = 0; k < texels; ++k) {
    for (std::size_t c = 0; c < 3; ++c) planes[c][k] = s.radiance.pixels[3 * k + c];
    planes[3][k] = s.valid[k] ? 1.0f : 0.0f;
  }
  write_planes(stem + ".exr", s.radiance.width, s.radiance.height, {"R", "G", "B", "A"}, planes);
  json passes = json::array();
  for (const hemilight::cache_stats& p : s.passes)
    passes.push_back({{"hemicubes", p.hemicubes}, {"records", p.records}, {"invalid_samples", p.invalid_samples}, {"seconds", p.seconds}});
  const json j = {{"format", "hemilight_pass_state"}, {"version", 1}, {"name", name}, {"pass", s.pass}, {"shards", s.shard_count},
                  {"key", key_text(s.key)}, {"width", s.radiance.width}, {"height", s.radiance.height}, {"passes", passes},
                  {"values", file_name(stem + ".exr")}};
  write_json(stem + ".json", j);
}

bake_pass_state read_state(const std::string& stem) {
  const std::string path = stem + ".json";
  const json j = read_json(path, "hemilight_pass_state");
  bake_pass_state s;
  s.pass = field<int>(j, "pass", path);
  s.shard_count = field<int>(j, "shards", path);
  s.key = parse_key(field<std::string>(j, "key", path), path);
  const int width = field<int>(j, "width", path), height = field<int>(j, "height", path);
  if (width < 1 || height < 1 || std::size_t(width) * std::size_t(height) > hemilight::max_image_pixels)
    throw std::runtime_error("'" + path + "': the atlas size " + std::to_string(width) + " x " + std::to_string(height) + " is out of range");
  const json& passes = j.contains("passes") ? j.at("passes") : json();
  if (!passes.is_array()) throw std::runtime_error("'" + path + "': \"passes\" is not an array");
  for (const json& p : passes) {
    hemilight::cache_stats cs;
    cs.hemicubes = field<std::size_t>(p, "hemicubes", path);
    cs.records = field<std::size_t>(p, "records", path);
    cs.invalid_samples = field<std::size_t>(p, "invalid_samples", path);
    cs.invalid_points = cs.invalid_samples;
    cs.seconds = field<double>(p, "seconds", path);
    s.passes.push_back(cs);
  }
  const std::vector<std::vector<float>> planes = read_planes(stem + ".exr", width, height, {"R", "G", "B", "A"});
  s.radiance = hemilight::image::make(width, height, 3);
  const std::size_t texels = std::size_t(width) * std::size_t(height);
  s.valid.resize(texels);
  for (std::size_t k = 0; k < texels; ++k) {
    for (std::size_t c = 0; c < 3; ++c) s.radiance.pixels[3 * k + c] = planes[c][k];
    s.valid[k] = planes[3][k] != 0.0f ? 1 : 0;
  }
  return s;
}

}  // namespace shard_files
