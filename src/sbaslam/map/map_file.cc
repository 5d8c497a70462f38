#include "sbaslam/map/map_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <string_view>
#include <type_traits>
#include <unordered_map>

#include "sbaslam/core/error.h"
#include "sbaslam/core/input_file.h"
#include "sbaslam/core/output_file.h"

namespace sbaslam::map {
namespace {

constexpr std::array<char, 12> kMagic = {'S', 'B', 'A', 'S', 'L', 'A',
                                         'M', '-', 'M', 'A', 'P', '\n'};
// 2: the rig records its lens (model and distortion coefficients).
// 3: keyframes keep each keypoint's S_init (Saliency.map_ba_depth: "point").
constexpr std::uint32_t kVersion = 3;
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr std::uint64_t kNone = std::numeric_limits<std::uint64_t>::max();
constexpr int kDescriptorBytes = 32;
// Bounds on counts read from a file, so that a corrupt count fails cleanly instead of allocating.
constexpr std::uint64_t kMaxKeypoints = 1u << 20;
constexpr std::uint64_t kMaxItems = std::uint64_t{1} << 32;

static_assert(std::is_trivially_copyable_v<feature::OrbKeypoint> &&
              sizeof(feature::OrbKeypoint) == 5 * sizeof(float) + sizeof(int));

// Written as two words: a struct with padding would put undefined bytes in the file.
struct IdAndValue {
  std::uint64_t id = 0;
  std::int64_t value = 0;
};

class Writer {
 public:
  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  template <typename T>
  void put_array(const std::vector<T>& values) {
    put<std::uint64_t>(values.size());
    // An empty vector's data() may be null, which append and memcpy must not be given.
    if (!values.empty())
      bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void put_bytes(const void* data, std::size_t n) {
    bytes_.append(static_cast<const char*>(data), n);
  }
  void put_pose(const SE3& T) {
    const Quat& q = T.quaternion();
    for (double v : {q.x(), q.y(), q.z(), q.w()}) put(v);
    for (int i = 0; i < 3; ++i) put(T.translation()[i]);
  }
  void put_vec3(const Vec3& v) {
    for (int i = 0; i < 3; ++i) put(v[i]);
  }
  template <typename... Fields>
  void put_fields(const Fields&... fields) {
    (put(fields), ...);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  Reader(std::string bytes, std::string path) : bytes_(std::move(bytes)), path_(std::move(path)) {}

  template <typename T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, take(sizeof(T)), sizeof(T));
    return value;
  }
  // A count of items of at least `item_bytes` each: more than the rest of the file holds is
  // corrupt, and is refused before anything is allocated for it.
  std::uint64_t get_count(std::uint64_t limit, const char* what, std::size_t item_bytes = 1) {
    const auto n = get<std::uint64_t>();
    if (n > limit) fail("{}: corrupt map file ({} {} at byte {})", path_, n, what, offset_ - 8);
    const std::size_t left = bytes_.size() - offset_;
    if (n > left / item_bytes)
      fail("{}: truncated map file ({} {} at byte {}, {} bytes left)", path_, n, what, offset_ - 8,
           left);
    return n;
  }
  template <typename T>
  std::vector<T> get_array(std::uint64_t limit, const char* what) {
    std::vector<T> values(get_count(limit, what, sizeof(T)));
    if (!values.empty())
      std::memcpy(values.data(), take(values.size() * sizeof(T)), values.size() * sizeof(T));
    return values;
  }
  const char* take(std::size_t n) {
    if (n > bytes_.size() - offset_)
      fail("{}: truncated map file (needs {} more bytes at byte {} of {})", path_, n, offset_,
           bytes_.size());
    const char* p = bytes_.data() + offset_;
    offset_ += n;
    return p;
  }
  SE3 get_pose() {
    double q[4];
    for (double& v : q) v = get<double>();
    const Vec3 t = get_vec3();
    const Quat quat(q[3], q[0], q[1], q[2]);
    if (!std::isfinite(quat.norm()) || std::abs(quat.norm() - 1.0) > 1e-6 || !t.allFinite())
      fail("{}: corrupt map file (a pose that is not a rigid motion at byte {})", path_, offset_);
    return SE3(SO3::from_unit_quaternion(quat), t);
  }
  Vec3 get_vec3() {
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = get<double>();
    return v;
  }
  bool at_end() const { return offset_ == bytes_.size(); }
  std::string_view prefix(std::size_t n) const {
    return std::string_view(bytes_).substr(0, std::min(n, bytes_.size()));
  }
  const std::string& path() const { return path_; }

 private:
  std::string bytes_;
  std::string path_;
  std::size_t offset_ = 0;
};

// What a map is made with: a map made with another camera cannot be tracked with this one.
struct RigSignature {
  std::int32_t width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0, bf = 0, th_depth = 0;
  std::uint8_t stereo = 0, rgbd = 0;
  std::int32_t levels = 0;
  double scale_factor = 0;
  // The keypoints were undistorted with this lens: 0 radial-tangential (k1, k2, p1, p2, k3),
  // 1 Kannala-Brandt (k1..k4, 0).
  std::uint8_t lens_model = 0;
  std::array<double, 5> lens = {};

  static RigSignature of(const CameraRig& rig) {
    RigSignature s;
    s.width = rig.width;
    s.height = rig.height;
    const PinholeIntrinsics& k = rig.camera.intrinsics();
    s.fx = k.fx;
    s.fy = k.fy;
    s.cx = k.cx;
    s.cy = k.cy;
    s.bf = rig.bf;
    s.th_depth = rig.th_depth;
    s.stereo = rig.stereo;
    s.rgbd = rig.rgbd;
    s.levels = rig.levels.size();
    s.scale_factor = rig.levels.size() > 1 ? rig.levels.scale[1] : 1.0;
    s.lens_model = rig.camera.is_fisheye() ? 1 : 0;
    if (rig.camera.is_fisheye()) {
      const KannalaBrandtDistortion& f = rig.camera.fisheye();
      s.lens = {f.k1, f.k2, f.k3, f.k4, 0.0};
    } else {
      const RadTanDistortion& d = rig.camera.distortion();
      s.lens = {d.k1, d.k2, d.p1, d.p2, d.k3};
    }
    return s;
  }
  void write(Writer& out) const {
    out.put_fields(width, height, fx, fy, cx, cy, bf, th_depth, stereo, rgbd, levels, scale_factor,
                   lens_model);
    for (double v : lens) out.put_fields(v);
  }
  static RigSignature read(Reader& in) {
    RigSignature s;
    s.width = in.get<std::int32_t>();
    s.height = in.get<std::int32_t>();
    for (double* v : {&s.fx, &s.fy, &s.cx, &s.cy, &s.bf, &s.th_depth}) *v = in.get<double>();
    s.stereo = in.get<std::uint8_t>();
    s.rgbd = in.get<std::uint8_t>();
    s.levels = in.get<std::int32_t>();
    s.scale_factor = in.get<double>();
    s.lens_model = in.get<std::uint8_t>();
    for (double& v : s.lens) v = in.get<double>();
    return s;
  }
};

bool nearly_equal(double a, double b) {
  return std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)});
}

std::string sensor_name(const RigSignature& s) {
  return s.rgbd ? "RGB-D" : s.stereo ? "stereo" : "monocular";
}

std::string lens_name(const RigSignature& s) {
  return s.lens_model == 1 ? "Kannala-Brandt fisheye" : "radial-tangential";
}

void check_rig(const RigSignature& file, const RigSignature& rig, const std::string& path) {
  if (sensor_name(file) != sensor_name(rig))
    fail("{}: the map was made with a {} camera, this run is {}", path, sensor_name(file),
         sensor_name(rig));
  if (file.width != rig.width || file.height != rig.height)
    fail("{}: the map was made with {}x{} images, this run has {}x{}", path, file.width,
         file.height, rig.width, rig.height);
  const std::array<std::pair<const char*, std::pair<double, double>>, 7> values = {{
      {"fx", {file.fx, rig.fx}},
      {"fy", {file.fy, rig.fy}},
      {"cx", {file.cx, rig.cx}},
      {"cy", {file.cy, rig.cy}},
      {"bf (baseline times fx)", {file.bf, rig.bf}},
      {"ThDepth", {file.th_depth, rig.th_depth}},
      {"ORBextractor.scaleFactor", {file.scale_factor, rig.scale_factor}},
  }};
  for (const auto& [name, pair] : values)
    if (!nearly_equal(pair.first, pair.second))
      fail("{}: the map was made with {} {}, this run has {}", path, name, pair.first, pair.second);
  if (file.lens_model != rig.lens_model)
    fail("{}: the map was made with a {} lens, this run has a {} one", path, lens_name(file),
         lens_name(rig));
  for (std::size_t i = 0; i < file.lens.size(); ++i)
    if (!nearly_equal(file.lens[i], rig.lens[i]))
      fail("{}: the map was made with lens distortion coefficient {} = {}, this run has {}", path,
           i + 1, file.lens[i], rig.lens[i]);
  if (file.levels != rig.levels)
    fail("{}: the map was made with {} pyramid levels, this run has {}", path, file.levels,
         rig.levels);
}

void check_header(Reader& in) {
  const std::string& path = in.path();
  // ORB-SLAM3's atlas is a boost archive, text or binary; both name themselves near the start.
  if (in.prefix(64).find("serialization::archive") != std::string_view::npos)
    fail(
        "{}: not an sba-slam map file (it is a boost archive, as ORB-SLAM3's atlas files are; "
        "sba-slam cannot read those)",
        path);
  const char* magic = in.take(kMagic.size());
  if (!std::equal(kMagic.begin(), kMagic.end(), magic)) fail("{}: not an sba-slam map file", path);
  if (in.get<std::uint32_t>() != kByteOrderMark)
    fail("{}: the map file was written on a machine of the other byte order", path);
  const auto version = in.get<std::uint32_t>();
  if (version != kVersion)
    fail("{}: map file version {}, this build reads version {}", path, version, kVersion);
}

}  // namespace

// The friend of KeyFrame, MapPoint and Map that writes and restores their private state.
class MapFile {
 public:
  static MapFileSummary save(const Map& map, const CameraRig& rig, const std::string& path);
  static MapFileSummary load(const std::string& path, const CameraRig& rig, Map& map);

 private:
  static void put_keyframe(Writer& out, const KeyFrame& kf);
  static void put_map_point(Writer& out, const MapPoint& mp);
  static KeyFrame* get_keyframe(Reader& in, const CameraRig& rig, Map& map);
  static void get_map_point(Reader& in, Map& map,
                            const std::unordered_map<std::uint64_t, KeyFrame*>& keyframes);
  static void get_graph(Reader& in, KeyFrame& kf,
                        const std::unordered_map<std::uint64_t, KeyFrame*>& keyframes);
};

namespace {

std::uint64_t id_or_none(const KeyFrame* kf) {
  return kf && !kf->is_bad() ? kf->id() : kNone;
}

MapFileSummary summary_of(const Map& map) {
  MapFileSummary summary;
  summary.keyframes = map.keyframe_count();
  summary.map_points = map.map_point_count();
  summary.maps = map.live_keyframes_per_map().size();
  std::size_t most = 0;
  for (const auto& [id, count] : map.live_keyframes_per_map())
    if (count > most) {
      most = count;
      summary.biggest_map_id = id;
    }
  for (const KeyFrame* kf : map.keyframes())
    summary.max_frame_id = std::max(summary.max_frame_id, kf->frame_id());
  return summary;
}

KeyFrame* keyframe_by_id(std::uint64_t id,
                         const std::unordered_map<std::uint64_t, KeyFrame*>& keyframes,
                         const std::string& path) {
  const auto it = keyframes.find(id);
  if (it == keyframes.end()) fail("{}: corrupt map file (no keyframe {})", path, id);
  return it->second;
}

}  // namespace

void MapFile::put_keyframe(Writer& out, const KeyFrame& kf) {
  out.put<std::uint64_t>(kf.id_);
  out.put<std::uint64_t>(kf.frame_id_);
  out.put<std::uint64_t>(kf.map_id_);
  out.put<double>(kf.timestamp_);
  out.put_pose(kf.T_cw_);
  const Measurements& m = *kf.measurements_;
  out.put_array(m.keypoints);
  out.put_array(m.keypoints_un);
  for (std::size_t i = 0; i < m.size(); ++i) out.put_bytes(m.descriptor(i), kDescriptorBytes);
  out.put_array(m.u_right);
  out.put_array(m.depth);
  out.put_array(m.weights);
  out.put_array(m.s_init);
}

void MapFile::put_map_point(Writer& out, const MapPoint& mp) {
  out.put<std::uint64_t>(mp.id_);
  out.put<std::uint64_t>(mp.first_keyframe_id_);
  out.put<std::uint64_t>(id_or_none(mp.reference_));
  out.put_vec3(mp.position_);
  out.put_vec3(mp.normal_);
  out.put<double>(mp.min_distance_);
  out.put<double>(mp.max_distance_);
  out.put<std::int32_t>(mp.visible_);
  out.put<std::int32_t>(mp.found_);
  out.put<std::uint8_t>(!mp.descriptor_.empty());
  if (!mp.descriptor_.empty()) out.put_bytes(mp.descriptor_.ptr(), kDescriptorBytes);
  std::vector<IdAndValue> observations;
  for (const auto& [kf, keypoint] : mp.observations_)
    if (!kf->is_bad()) observations.push_back({kf->id(), static_cast<std::int64_t>(keypoint)});
  out.put_array(observations);
}

MapFileSummary MapFile::save(const Map& map, const CameraRig& rig, const std::string& path) {
  Writer out;
  out.put_bytes(kMagic.data(), kMagic.size());
  out.put(kByteOrderMark);
  out.put(kVersion);
  RigSignature::of(rig).write(out);
  out.put<std::uint64_t>(map.next_map_id_);
  out.put<std::uint64_t>(map.next_keyframe_id_);
  out.put<std::uint64_t>(map.next_map_point_id_);
  out.put<std::uint64_t>(id_or_none(map.first_keyframe_));

  const std::vector<KeyFrame*> keyframes = map.keyframes();
  out.put<std::uint64_t>(keyframes.size());
  for (const KeyFrame* kf : keyframes) put_keyframe(out, *kf);
  const std::vector<MapPoint*> points = map.map_points();
  out.put<std::uint64_t>(points.size());
  for (const MapPoint* mp : points) put_map_point(out, *mp);
  // The graph last: it names keyframes, which are then all known to the reader.
  for (const KeyFrame* kf : keyframes) {
    out.put<std::uint8_t>(kf->origin_);
    out.put<std::uint8_t>(kf->not_erase_);
    out.put<std::uint8_t>(kf->first_connection_);
    out.put<std::uint64_t>(id_or_none(kf->parent_));
    std::vector<IdAndValue> connections;
    for (const auto& [other, weight] : kf->connection_weights_)
      if (!other->is_bad()) connections.push_back({other->id(), weight});
    out.put_array(connections);
    std::vector<std::uint64_t> loop_edges;
    for (const KeyFrame* other : kf->loop_edges_)
      if (!other->is_bad()) loop_edges.push_back(other->id());
    out.put_array(loop_edges);
  }
  write_output_file(path, out.bytes());
  return summary_of(map);
}

KeyFrame* MapFile::get_keyframe(Reader& in, const CameraRig& rig, Map& map) {
  const auto id = in.get<std::uint64_t>();
  const auto frame_id = in.get<std::uint64_t>();
  const auto map_id = in.get<std::uint64_t>();
  const auto timestamp = in.get<double>();
  const SE3 T_cw = in.get_pose();
  auto m = std::make_shared<Measurements>();
  m->keypoints = in.get_array<feature::OrbKeypoint>(kMaxKeypoints, "keypoints");
  m->keypoints_un = in.get_array<feature::OrbKeypoint>(kMaxKeypoints, "keypoints");
  const int n = static_cast<int>(m->keypoints.size());
  m->descriptors = cv::Mat(n, kDescriptorBytes, CV_8U);
  if (n > 0) std::memcpy(m->descriptors.data, in.take(n * kDescriptorBytes), n * kDescriptorBytes);
  m->u_right = in.get_array<float>(kMaxKeypoints, "right columns");
  m->depth = in.get_array<float>(kMaxKeypoints, "depths");
  m->weights = in.get_array<float>(kMaxKeypoints, "weights");
  m->s_init = in.get_array<float>(kMaxKeypoints, "saliency values");
  const std::size_t size = m->keypoints.size();
  if (m->keypoints_un.size() != size || m->u_right.size() != size || m->depth.size() != size ||
      (!m->weights.empty() && m->weights.size() != size) ||
      (!m->s_init.empty() && m->s_init.size() != size))
    fail("{}: corrupt map file (keyframe {} has lists of different lengths)", in.path(), id);
  for (const feature::OrbKeypoint& kp : m->keypoints_un)
    if (kp.octave < 0 || kp.octave >= rig.levels.size() || !std::isfinite(kp.x) ||
        !std::isfinite(kp.y))
      fail("{}: corrupt map file (keyframe {} has a keypoint off the pyramid)", in.path(), id);
  m->grid = match::FeatureGrid(m->keypoints_un, rig.bounds);
  auto kf = std::make_unique<KeyFrame>(id, frame_id, timestamp, T_cw, std::move(m), &rig, &map);
  kf->map_id_ = map_id;
  KeyFrame* raw = kf.get();
  if (!map.keyframes_.insert(raw).second)
    fail("{}: corrupt map file (keyframe {} twice)", in.path(), id);
  map.keyframe_storage_.push_back(std::move(kf));
  ++map.live_keyframes_per_map_[map_id];
  return raw;
}

void MapFile::get_map_point(Reader& in, Map& map,
                            const std::unordered_map<std::uint64_t, KeyFrame*>& keyframes) {
  const auto id = in.get<std::uint64_t>();
  const auto first_keyframe_id = in.get<std::uint64_t>();
  const auto reference_id = in.get<std::uint64_t>();
  const Vec3 position = in.get_vec3();
  const Vec3 normal = in.get_vec3();
  const auto min_distance = in.get<double>();
  const auto max_distance = in.get<double>();
  const auto visible = in.get<std::int32_t>();
  const auto found = in.get<std::int32_t>();
  const bool has_descriptor = in.get<std::uint8_t>() != 0;
  const char* descriptor = has_descriptor ? in.take(kDescriptorBytes) : nullptr;
  const auto observations = in.get_array<IdAndValue>(kMaxItems, "observations");
  if (!position.allFinite() || !normal.allFinite())
    fail("{}: corrupt map file (map point {} is not finite)", in.path(), id);

  KeyFrame* reference =
      reference_id == kNone ? nullptr : keyframe_by_id(reference_id, keyframes, in.path());
  auto mp = std::make_unique<MapPoint>(id, position, reference, &map);
  mp->first_keyframe_id_ = first_keyframe_id;
  mp->normal_ = normal;
  mp->min_distance_ = min_distance;
  mp->max_distance_ = max_distance;
  mp->visible_ = visible;
  mp->found_ = found;
  if (descriptor) {
    mp->descriptor_ = cv::Mat(1, kDescriptorBytes, CV_8U);
    std::memcpy(mp->descriptor_.data, descriptor, kDescriptorBytes);
  }
  MapPoint* raw = mp.get();
  for (const IdAndValue& observation : observations) {
    KeyFrame* kf = keyframe_by_id(observation.id, keyframes, in.path());
    const auto keypoint = static_cast<std::size_t>(observation.value);
    if (observation.value < 0 || keypoint >= kf->keypoint_count() || kf->map_points_[keypoint])
      fail("{}: corrupt map file (map point {} in keypoint {} of keyframe {})", in.path(), id,
           observation.value, observation.id);
    raw->add_observation(kf, keypoint);
    kf->map_points_[keypoint] = raw;
  }
  if (!raw->reference_ && !raw->observations_.empty())
    raw->reference_ = raw->observations_.begin()->first;
  if (!map.map_points_.insert(raw).second)
    fail("{}: corrupt map file (map point {} twice)", in.path(), id);
  map.map_point_storage_.push_back(std::move(mp));
}

void MapFile::get_graph(Reader& in, KeyFrame& kf,
                        const std::unordered_map<std::uint64_t, KeyFrame*>& keyframes) {
  kf.origin_ = in.get<std::uint8_t>() != 0;
  kf.not_erase_ = in.get<std::uint8_t>() != 0;
  kf.first_connection_ = in.get<std::uint8_t>() != 0;
  const auto parent = in.get<std::uint64_t>();
  if (parent != kNone) {
    kf.parent_ = keyframe_by_id(parent, keyframes, in.path());
    kf.parent_->children_.insert(&kf);
  }
  for (const IdAndValue& connection : in.get_array<IdAndValue>(kMaxItems, "connections"))
    kf.connection_weights_[keyframe_by_id(connection.id, keyframes, in.path())] =
        static_cast<int>(connection.value);
  kf.sort_connections();
  for (const std::uint64_t id : in.get_array<std::uint64_t>(kMaxItems, "loop edges"))
    kf.loop_edges_.insert(keyframe_by_id(id, keyframes, in.path()));
}

MapFileSummary MapFile::load(const std::string& path, const CameraRig& rig, Map& map) {
  if (!map.keyframes_.empty() || !map.map_points_.empty())
    throw std::logic_error("load_map: the map is not empty");
  Reader in(read_input_file(path, "map file"), path);
  check_header(in);
  check_rig(RigSignature::read(in), RigSignature::of(rig), path);
  map.next_map_id_ = in.get<std::uint64_t>();
  map.next_keyframe_id_ = in.get<std::uint64_t>();
  map.next_map_point_id_ = in.get<std::uint64_t>();
  const auto first_keyframe = in.get<std::uint64_t>();

  std::unordered_map<std::uint64_t, KeyFrame*> by_id;
  std::vector<KeyFrame*> keyframes(in.get_count(kMaxItems, "keyframes"));
  for (KeyFrame*& kf : keyframes) {
    kf = get_keyframe(in, rig, map);
    by_id[kf->id()] = kf;
    if (kf->id() >= map.next_keyframe_id_ || kf->map_id() >= map.next_map_id_)
      fail("{}: corrupt map file (keyframe {} beyond the file's counters)", path, kf->id());
  }
  const std::uint64_t points = in.get_count(kMaxItems, "map points");
  for (std::uint64_t i = 0; i < points; ++i) get_map_point(in, map, by_id);
  for (KeyFrame* kf : keyframes) get_graph(in, *kf, by_id);
  if (!in.at_end()) fail("{}: corrupt map file (bytes after the end of the map)", path);
  if (points != map.map_points_.size()) fail("{}: corrupt map file (map point ids repeat)", path);
  for (const MapPoint* mp : map.map_points_)
    if (mp->id() >= map.next_map_point_id_)
      fail("{}: corrupt map file (map point {} beyond the file's counters)", path, mp->id());
  const auto first = by_id.find(first_keyframe);
  map.first_keyframe_ = first != by_id.end()     ? first->second
                        : map.keyframes_.empty() ? nullptr
                                                 : *map.keyframes_.begin();
  return summary_of(map);
}

MapFileSummary save_map(const Map& map, const CameraRig& rig, const std::string& path) {
  return MapFile::save(map, rig, path);
}

MapFileSummary load_map(const std::string& path, const CameraRig& rig, Map& map) {
  return MapFile::load(path, rig, map);
}

}  // namespace sbaslam::map
