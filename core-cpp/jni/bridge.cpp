// The registered natives of org.pdnav.app.nav.NativeBridge (JNI_OnLoad + RegisterNatives).
// Each native converts its arguments, locks the handle's mutex, forwards to the core
// (fusion::Navigator, io::LogWriter, io::LogReader) and converts the result back.
#include <jni.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "jni_support.h"
#include "pdnav/fusion/navigator.h"
#include "pdnav/geo/geodesic.h"
#include "pdnav/io/log_reader.h"
#include "pdnav/io/sample_source.h"
#include "pdnav/io/log_writer.h"
#include "pdnav/route/router.h"
#include "pdnav/route/walk_graph.h"
#include "pdnav/terrain/dem.h"
#include "sample_codec.h"

namespace pdnav::jni {
namespace {

using NavHandle = Handle<fusion::Navigator>;
using RecHandle = Handle<io::LogWriter>;
using ReaderHandle = Handle<std::unique_ptr<io::SampleSource>>;

constexpr const char* kBridgeClass = "org/pdnav/app/nav/NativeBridge";
constexpr const char* kEstimateClass = "org/pdnav/app/nav/NavEstimate";
constexpr const char* kOutputClass = "org/pdnav/app/nav/NavOutput";
constexpr const char* kEstimateCtor = "(JIILjava/lang/String;DDDDDDDDD)V";
constexpr const char* kOutputCtor =
    "(Lorg/pdnav/app/nav/NavEstimate;[Lorg/pdnav/app/nav/NavEstimate;J[D)V";

JavaBatchArrays arrays(jintArray k, jlongArray t, jlongArray i, jdoubleArray d, jobjectArray s,
                       jbyteArray b) {
  return JavaBatchArrays{k, t, i, d, s, b};
}

/// Classes and constructors the bridge builds, looked up once in JNI_OnLoad (global
/// references; read-only afterwards). FindClass per call is slow, and on a thread the
/// native side attached itself it would search the system class loader, not the app's.
struct ClassCache {
  jclass estimate = nullptr;
  jclass output = nullptr;
  jclass string = nullptr;
  jmethodID estimate_ctor = nullptr;
  jmethodID output_ctor = nullptr;
};
ClassCache g_classes;  // set once at load, before any native can run

bool load_classes(JNIEnv* env, ClassCache& c) {
  auto global = [env](const char* name) -> jclass {
    jclass local = env->FindClass(name);
    if (local == nullptr) return nullptr;
    auto g = static_cast<jclass>(env->NewGlobalRef(local));
    env->DeleteLocalRef(local);
    return g;
  };
  c.estimate = global(kEstimateClass);
  c.output = global(kOutputClass);
  c.string = global("java/lang/String");
  if (c.estimate == nullptr || c.output == nullptr || c.string == nullptr) return false;
  c.estimate_ctor = env->GetMethodID(c.estimate, "<init>", kEstimateCtor);
  c.output_ctor = env->GetMethodID(c.output, "<init>", kOutputCtor);
  return c.estimate_ctor != nullptr && c.output_ctor != nullptr;
}

/// f(object) under the handle's lock, returned by value: the result is a copy taken under the
/// lock, converted to Java objects after it is released.
template <class T, class F>
auto copy_locked(Handle<T>& h, F f) {
  const std::lock_guard<std::mutex> lock(h.mutex);
  return f(h.object);
}

jobject new_estimate(JNIEnv* env, const Estimate& e) {
  jclass c = g_classes.estimate;
  jmethodID ctor = g_classes.estimate_ctor;
  jstring reason = new_string(env, e.reason);
  const bool has_position = e.status != EstimateStatus::kNotInitialized;
  const double nan = std::nan("");
  jobject o = env->NewObject(c, ctor, static_cast<jlong>(e.t_ns), static_cast<jint>(e.engine),
                             static_cast<jint>(e.status), reason,
                             has_position ? e.position.lat_deg() : nan,
                             has_position ? e.position.lon_deg() : nan,
                             has_position ? e.position.h_m : nan, e.en_m.x(), e.en_m.y(),
                             e.cov_en_m2(0, 0), e.cov_en_m2(0, 1), e.cov_en_m2(1, 1),
                             e.vertical_sigma_m);
  env->DeleteLocalRef(reason);
  if (o == nullptr) throw JavaError(kRuntime, "NavEstimate allocation failed");
  return o;
}

// ---- static information -------------------------------------------------------------

jintArray layout(JNIEnv* env, jclass) {
  return guarded<jintArray>(env, nullptr, [&] {
    const jint v[] = {kLayoutVersion, static_cast<jint>(kInts), static_cast<jint>(kDoubles),
                      static_cast<jint>(kStrings), static_cast<jint>(kBytes), kKinds};
    jintArray a = env->NewIntArray(6);
    env->SetIntArrayRegion(a, 0, 6, v);
    return a;
  });
}

jobjectArray names(JNIEnv* env, const std::vector<std::string>& v) {
  jobjectArray a = env->NewObjectArray(static_cast<jsize>(v.size()), g_classes.string, nullptr);
  if (a == nullptr) throw JavaError(kRuntime, "String[] allocation failed");
  for (std::size_t i = 0; i < v.size(); ++i) {
    jstring s = new_string(env, v[i]);
    env->SetObjectArrayElement(a, static_cast<jsize>(i), s);
    env->DeleteLocalRef(s);
  }
  return a;
}

jobjectArray engine_names(JNIEnv* env, jclass) {
  return guarded<jobjectArray>(env, nullptr, [&] {
    std::vector<std::string> v;
    for (auto k : {EngineKind::kNone, EngineKind::kDeadReckoning, EngineKind::kTerrain,
                   EngineKind::kRoute, EngineKind::kGnss}) {
      v.emplace_back(to_string(k));
    }
    return names(env, v);
  });
}

jobjectArray status_names(JNIEnv* env, jclass) {
  return guarded<jobjectArray>(env, nullptr, [&] {
    std::vector<std::string> v;
    for (auto s : {EstimateStatus::kNotInitialized, EstimateStatus::kOk, EstimateStatus::kDegraded,
                   EstimateStatus::kAmbiguous, EstimateStatus::kLost}) {
      v.emplace_back(to_string(s));
    }
    return names(env, v);
  });
}

// ---- navigator ------------------------------------------------------------------------

jlong nav_create(JNIEnv* env, jclass, jstring mode, jdouble lat, jdouble lon, jdouble sigma,
                 jdouble height, jboolean female, jstring dem, jstring graph, jobjectArray navs,
                 jint particles, jstring preset, jlong seed) {
  return guarded<jlong>(env, 0, [&] {
    fusion::NavigatorConfig c;
    // The app declares no mount: the phone may be anywhere on the walker (a chest mount, a hand,
    // a pocket), so the placement is estimated from the motion, as `pdnav replay` does; an app
    // session and its replay on the host then give the same track.
    c.mount = pdr::Mount::kAuto;
    c.mode = fusion::engine_mode_from_string(to_string(env, mode, "mode"));
    c.start_lat_deg = lat;
    c.start_lon_deg = lon;
    c.start_sigma_m = sigma;
    c.user_height_m = height;
    c.user_female = female == JNI_TRUE;
    c.dem_path = to_string(env, dem, "demPath");
    c.graph_path = to_string(env, graph, "graphPath");
    c.nav_paths = to_strings(env, navs, "navPaths");
    if (particles <= 0) {
      throw JavaError(kIllegalArgument, "particles must be > 0, got " + std::to_string(particles));
    }
    c.particles = particles;
    c.terrain_preset = to_string(env, preset, "terrainPreset");
    auto* h = new NavHandle(c, static_cast<std::uint64_t>(seed));
    return to_handle(h);
  });
}

void nav_feed(JNIEnv* env, jclass, jlong handle, jint n, jintArray k, jlongArray t, jlongArray i,
              jdoubleArray d, jobjectArray s, jbyteArray b) {
  guarded_void(env, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const CopiedBatch batch(env, n, arrays(k, t, i, d, s, b));
    std::vector<Sample> samples;
    samples.reserve(batch.view().n);
    for (std::size_t r = 0; r < batch.view().n; ++r) samples.push_back(decode_row(batch.view(), r));
    const std::lock_guard<std::mutex> lock(h.mutex);
    for (const auto& x : samples) h.object.feed(x);
  });
}

void nav_set_start(JNIEnv* env, jclass, jlong handle, jdouble lat, jdouble lon, jdouble sigma,
                   jlong t_ns) {
  guarded_void(env, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    if (!std::isfinite(lat) || !std::isfinite(lon) || !(sigma > 0.0) || std::fabs(lat) > 90.0 ||
        std::fabs(lon) > 180.0) {
      throw JavaError(kIllegalArgument, "start position needs |lat| <= 90, |lon| <= 180, sigma > 0");
    }
    const std::lock_guard<std::mutex> lock(h.mutex);
    h.object.set_start(lat, lon, sigma, t_ns);
  });
}

jobject nav_estimate(JNIEnv* env, jclass, jlong handle) {
  return guarded<jobject>(env, nullptr, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const Estimate e = copy_locked(h, [](fusion::Navigator& n) { return n.estimate(); });
    return new_estimate(env, e);
  });
}

jobject nav_output(JNIEnv* env, jclass, jlong handle, jint max_particles) {
  return guarded<jobject>(env, nullptr, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    if (max_particles < 0) throw JavaError(kIllegalArgument, "maxParticles must be >= 0");
    const fusion::NavigatorOutput out =
        copy_locked(h, [&](fusion::Navigator& n) { return n.output(static_cast<std::size_t>(max_particles)); });
    jobject best = new_estimate(env, out.estimate);
    jobjectArray engines =
        env->NewObjectArray(static_cast<jsize>(out.engines.size()), g_classes.estimate, nullptr);
    for (std::size_t i = 0; i < out.engines.size(); ++i) {
      jobject e = new_estimate(env, out.engines[i]);
      env->SetObjectArrayElement(engines, static_cast<jsize>(i), e);
      env->DeleteLocalRef(e);
    }
    std::vector<double> en;
    en.reserve(out.particles_en_m.size() * 2);
    for (const auto& p : out.particles_en_m) {
      en.push_back(p.x());
      en.push_back(p.y());
    }
    jdoubleArray particles = env->NewDoubleArray(static_cast<jsize>(en.size()));
    env->SetDoubleArrayRegion(particles, 0, static_cast<jsize>(en.size()), en.data());
    jobject o = env->NewObject(g_classes.output, g_classes.output_ctor, best, engines,
                               static_cast<jlong>(out.steps), particles);
    return o;
  });
}

jobjectArray nav_ignored(JNIEnv* env, jclass, jlong handle) {
  return guarded<jobjectArray>(env, nullptr, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const std::vector<std::pair<std::string, std::int64_t>> ign =
        copy_locked(h, [](fusion::Navigator& n) { return n.ignored(); });
    std::vector<std::string> flat;  // reason, count, reason, count, ...
    for (const auto& [reason, count] : ign) {
      flat.push_back(reason);
      flat.push_back(std::to_string(count));
    }
    return names(env, flat);
  });
}

// Fused-estimate hand-overs (issue 14), flat: t_ns, from, to, reason, t_ns, from, ...
jobjectArray nav_mode_changes(JNIEnv* env, jclass, jlong handle) {
  return guarded<jobjectArray>(env, nullptr, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const std::vector<fusion::ModeChange> changes =
        copy_locked(h, [](fusion::Navigator& n) { return n.mode_changes(); });
    std::vector<std::string> flat;
    for (const fusion::ModeChange& c : changes) {
      flat.push_back(std::to_string(c.t_ns));
      flat.push_back(fusion::to_string(c.from));
      flat.push_back(fusion::to_string(c.to));
      flat.push_back(c.reason);
    }
    return names(env, flat);
  });
}

jdoubleArray to_java(JNIEnv* env, const std::vector<double>& v);

/// Per-step estimates since the last call, 8 doubles per step (layout in NativeBridge.kt):
/// t_ns, lat, lon, sigma_east_m, sigma_north_m, corr_en, heading_rad, distance_m.
/// lat/lon/sigmas/corr are NaN for a step before the start position is known.
constexpr std::size_t kStepDoubles = 8;

jdoubleArray nav_take_steps(JNIEnv* env, jclass, jlong handle) {
  return guarded<jdoubleArray>(env, nullptr, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const std::vector<fusion::StepEstimate> steps =
        copy_locked(h, [](fusion::Navigator& n) { return n.take_steps(); });
    const double nan = std::nan("");
    std::vector<double> flat;
    flat.reserve(steps.size() * kStepDoubles);
    for (const fusion::StepEstimate& s : steps) {
      const Estimate& e = s.estimate;
      const bool ok = e.valid();
      const double se = std::sqrt(std::max(0.0, e.cov_en_m2(0, 0)));
      const double sn = std::sqrt(std::max(0.0, e.cov_en_m2(1, 1)));
      const double corr = se > 0.0 && sn > 0.0 ? e.cov_en_m2(0, 1) / (se * sn) : 0.0;
      flat.insert(flat.end(), {static_cast<double>(e.t_ns), ok ? e.position.lat_deg() : nan,
                               ok ? e.position.lon_deg() : nan, ok ? se : nan, ok ? sn : nan,
                               ok ? corr : nan, s.heading_rad, s.distance_m});
    }
    return to_java(env, flat);
  });
}

void nav_finish(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto& h = from_handle<fusion::Navigator>(handle, "NativeNavigator");
    const std::lock_guard<std::mutex> lock(h.mutex);
    h.object.finish();
  });
}

void nav_close(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto* h = &from_handle<fusion::Navigator>(handle, "NativeNavigator");
    { const std::lock_guard<std::mutex> lock(h->mutex); }  // wait for a call in flight
    delete h;
  });
}

// ---- recorder (io::LogWriter) ---------------------------------------------------------

jlong rec_open(JNIEnv* env, jclass, jstring path, jstring device, jlong flush_ns, jboolean fsync) {
  return guarded<jlong>(env, 0, [&] {
    io::LogWriterOptions o;
    if (flush_ns <= 0) throw JavaError(kIllegalArgument, "flush interval must be > 0 ns");
    o.flush_interval_ns = flush_ns;
    o.fsync_on_flush = fsync == JNI_TRUE;
    o.device = to_string(env, device, "device");
    return to_handle(new RecHandle(to_string(env, path, "path"), o));
  });
}

void rec_write(JNIEnv* env, jclass, jlong handle, jint n, jintArray k, jlongArray t, jlongArray i,
               jdoubleArray d, jobjectArray s, jbyteArray b) {
  guarded_void(env, [&] {
    auto& h = from_handle<io::LogWriter>(handle, "NativeRecorder");
    const CopiedBatch batch(env, n, arrays(k, t, i, d, s, b));
    std::vector<Sample> samples;
    samples.reserve(batch.view().n);
    for (std::size_t r = 0; r < batch.view().n; ++r) samples.push_back(decode_row(batch.view(), r));
    const std::lock_guard<std::mutex> lock(h.mutex);
    for (const auto& x : samples) h.object.write(x);
  });
}

void rec_flush(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto& h = from_handle<io::LogWriter>(handle, "NativeRecorder");
    const std::lock_guard<std::mutex> lock(h.mutex);
    h.object.flush();
  });
}

jlong rec_lines(JNIEnv* env, jclass, jlong handle) {
  return guarded<jlong>(env, 0, [&] {
    auto& h = from_handle<io::LogWriter>(handle, "NativeRecorder");
    const std::lock_guard<std::mutex> lock(h.mutex);
    return static_cast<jlong>(h.object.lines_written());
  });
}

void rec_close(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto* h = &from_handle<io::LogWriter>(handle, "NativeRecorder");
    {
      const std::lock_guard<std::mutex> lock(h->mutex);
      h->object.close();
    }
    delete h;
  });
}

// ---- log reader (io::open_sample_source: session/GnssLogger log, Sensor Logger or phyphox
// folder/zip, GetSensorData file; the format from the content) ------------------------------

/// The app's replay shows an empty recording as empty (stats tell why); the CLI refuses it.
io::SourceOptions reader_options() {
  io::SourceOptions o;
  o.require_samples = false;
  return o;
}

jlong reader_open(JNIEnv* env, jclass, jstring path) {
  return guarded<jlong>(env, 0, [&] {
    return to_handle(new ReaderHandle(io::open_sample_source(to_string(env, path, "path"), io::Format::kAuto, reader_options())));
  });
}

jint reader_read(JNIEnv* env, jclass, jlong handle, jint max, jintArray k, jlongArray t,
                 jlongArray i, jdoubleArray d, jobjectArray s, jbyteArray b) {
  return guarded<jint>(env, 0, [&] {
    auto& h = from_handle<std::unique_ptr<io::SampleSource>>(handle, "NativeLogReader");
    if (max <= 0) throw JavaError(kIllegalArgument, "max must be > 0");
    const JavaBatchArrays a = arrays(k, t, i, d, s, b);
    check_batch_arrays(env, static_cast<std::size_t>(max), a);
    OutBatch out(static_cast<std::size_t>(max));
    std::size_t n = 0;
    {
      const std::lock_guard<std::mutex> lock(h.mutex);
      Sample sample;
      while (n < static_cast<std::size_t>(max) && h.object->next(sample)) {
        encode_row(sample, out.rows(), n);
        ++n;
      }
    }
    out.copy_to(env, n, a);
    return static_cast<jint>(n);
  });
}

jlongArray reader_stats(JNIEnv* env, jclass, jlong handle) {
  return guarded<jlongArray>(env, nullptr, [&] {
    auto& h = from_handle<std::unique_ptr<io::SampleSource>>(handle, "NativeLogReader");
    const std::lock_guard<std::mutex> lock(h.mutex);
    const auto& st = h.object->stats();
    const jlong v[] = {st.lines, st.samples, st.skipped_total()};
    jlongArray a = env->NewLongArray(3);
    env->SetLongArrayRegion(a, 0, 3, v);
    return a;
  });
}

jdouble reader_progress(JNIEnv* env, jclass, jlong handle) {
  return guarded<jdouble>(env, 0.0, [&] {
    auto& h = from_handle<std::unique_ptr<io::SampleSource>>(handle, "NativeLogReader");
    const std::lock_guard<std::mutex> lock(h.mutex);
    return h.object->progress();
  });
}

void reader_close(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto* h = &from_handle<std::unique_ptr<io::SampleSource>>(handle, "NativeLogReader");
    { const std::lock_guard<std::mutex> lock(h->mutex); }
    delete h;
  });
}

// ---- map data for the screen (read once per file, not per output) ----------------------

jdoubleArray to_java(JNIEnv* env, const std::vector<double>& v) {
  jdoubleArray a = env->NewDoubleArray(static_cast<jsize>(v.size()));
  if (a == nullptr) throw JavaError(kRuntime, "double[] allocation failed");
  env->SetDoubleArrayRegion(a, 0, static_cast<jsize>(v.size()), v.data());
  return a;
}

/// The walkway graph's edges as WGS84 polylines: lat, lon pairs, each edge ended by NaN, NaN.
jdoubleArray graph_polylines(JNIEnv* env, jclass, jstring path) {
  return guarded<jdoubleArray>(env, nullptr, [&] {
    const route::WalkGraph g = route::WalkGraph::load(to_string(env, path, "path"));
    std::vector<double> out;
    auto add = [&](const Eigen::Vector2d& en) {
      const geo::Geodetic p = g.frame().to_geodetic(geo::Enu(en.x(), en.y(), 0.0));
      out.push_back(p.lat_deg());
      out.push_back(p.lon_deg());
    };
    const double nan = std::nan("");
    for (std::size_t e = 0; e < g.edge_count(); ++e) {
      const auto& edge = g.edge(static_cast<std::int32_t>(e));
      add(g.node_en_m(edge.from));
      for (const auto& q : edge.shape_en_m) add(q);
      add(g.node_en_m(edge.to));
      out.push_back(nan);
      out.push_back(nan);
    }
    return to_java(env, out);
  });
}

/// A DEM tile's WGS84 bounds: min lat, min lon, max lat, max lon (of its ENU corners).
jdoubleArray dem_bounds(JNIEnv* env, jclass, jstring path) {
  return guarded<jdoubleArray>(env, nullptr, [&] {
    const terrain::Dem d = terrain::Dem::load(to_string(env, path, "path"));
    double lat0 = 90, lon0 = 180, lat1 = -90, lon1 = -180;
    for (double e : {d.min_e_m(), d.max_e_m()}) {
      for (double n : {d.min_n_m(), d.max_n_m()}) {
        const geo::Geodetic p = d.frame().to_geodetic(geo::Enu(e, n, 0.0));
        lat0 = std::min(lat0, p.lat_deg());
        lat1 = std::max(lat1, p.lat_deg());
        lon0 = std::min(lon0, p.lon_deg());
        lon1 = std::max(lon1, p.lon_deg());
      }
    }
    return to_java(env, {lat0, lon0, lat1, lon1});
  });
}

// ---- router (route::Router on a loaded walkway graph) ------------------------------------

using RouterHandle = Handle<route::Router>;

jlong route_open(JNIEnv* env, jclass, jstring path) {
  return guarded<jlong>(env, 0, [&] {
    auto graph = std::make_shared<const route::WalkGraph>(route::WalkGraph::load(to_string(env, path, "graphPath")));
    return to_handle(new RouterHandle(route::RouterOptions{}, std::move(graph)));
  });
}

/// [length_m, from_snap_m, to_snap_m, lat0, lon0, lat1, lon1, ...]; empty when no path.
jdoubleArray route_shortest(JNIEnv* env, jclass, jlong handle, jdouble from_lat, jdouble from_lon,
                            jdouble to_lat, jdouble to_lon) {
  return guarded<jdoubleArray>(env, nullptr, [&] {
    auto& h = from_handle<route::Router>(handle, "NativeRouter");
    route::RoutePath p;
    {
      const std::lock_guard<std::mutex> lock(h.mutex);
      p = h.object.shortest_geodetic(from_lat, from_lon, to_lat, to_lon);  // invalid_argument on NaN
    }
    std::vector<double> out;
    if (!p.found) return to_java(env, out);
    out.reserve(3 + 2 * p.polyline_en_m.size());
    out.insert(out.end(), {p.length_m, p.from_snap_m, p.to_snap_m});
    for (const auto& q : p.polyline_en_m) {
      const geo::Geodetic g = h.object.graph().frame().to_geodetic(geo::Enu(q.x(), q.y(), 0.0));
      out.push_back(g.lat_deg());
      out.push_back(g.lon_deg());
    }
    return to_java(env, out);
  });
}

void route_close(JNIEnv* env, jclass, jlong handle) {
  guarded_void(env, [&] {
    auto* h = &from_handle<route::Router>(handle, "NativeRouter");
    { const std::lock_guard<std::mutex> lock(h->mutex); }
    delete h;
  });
}

/// [distance_m, initial_bearing_rad] on the WGS84 ellipsoid (GeographicLib).
jdoubleArray geo_inverse(JNIEnv* env, jclass, jdouble lat1, jdouble lon1, jdouble lat2, jdouble lon2) {
  return guarded<jdoubleArray>(env, nullptr, [&] {
    const geo::GeodesicInverse r = geo::geodesic_inverse(lat1, lon1, lat2, lon2);
    return to_java(env, {r.distance_m, r.initial_bearing_rad});
  });
}

#define PDNAV_BATCH_SIG "I[I[J[J[D[Ljava/lang/String;[B"

const JNINativeMethod kMethods[] = {
    {const_cast<char*>("layout"), const_cast<char*>("()[I"), reinterpret_cast<void*>(&layout)},
    {const_cast<char*>("engineNames"), const_cast<char*>("()[Ljava/lang/String;"), reinterpret_cast<void*>(&engine_names)},
    {const_cast<char*>("statusNames"), const_cast<char*>("()[Ljava/lang/String;"), reinterpret_cast<void*>(&status_names)},
    {const_cast<char*>("navCreate"), const_cast<char*>("(Ljava/lang/String;DDDDZLjava/lang/String;Ljava/lang/String;[Ljava/lang/String;ILjava/lang/String;J)J"), reinterpret_cast<void*>(&nav_create)},
    {const_cast<char*>("navFeed"), const_cast<char*>("(J" PDNAV_BATCH_SIG ")V"), reinterpret_cast<void*>(&nav_feed)},
    {const_cast<char*>("navSetStart"), const_cast<char*>("(JDDDJ)V"), reinterpret_cast<void*>(&nav_set_start)},
    {const_cast<char*>("navEstimate"), const_cast<char*>("(J)Lorg/pdnav/app/nav/NavEstimate;"), reinterpret_cast<void*>(&nav_estimate)},
    {const_cast<char*>("navOutput"), const_cast<char*>("(JI)Lorg/pdnav/app/nav/NavOutput;"), reinterpret_cast<void*>(&nav_output)},
    {const_cast<char*>("navIgnored"), const_cast<char*>("(J)[Ljava/lang/String;"), reinterpret_cast<void*>(&nav_ignored)},
    {const_cast<char*>("navModeChanges"), const_cast<char*>("(J)[Ljava/lang/String;"), reinterpret_cast<void*>(&nav_mode_changes)},
    {const_cast<char*>("navTakeSteps"), const_cast<char*>("(J)[D"), reinterpret_cast<void*>(&nav_take_steps)},
    {const_cast<char*>("navFinish"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&nav_finish)},
    {const_cast<char*>("navClose"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&nav_close)},
    {const_cast<char*>("recOpen"), const_cast<char*>("(Ljava/lang/String;Ljava/lang/String;JZ)J"), reinterpret_cast<void*>(&rec_open)},
    {const_cast<char*>("recWrite"), const_cast<char*>("(J" PDNAV_BATCH_SIG ")V"), reinterpret_cast<void*>(&rec_write)},
    {const_cast<char*>("recFlush"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&rec_flush)},
    {const_cast<char*>("recLines"), const_cast<char*>("(J)J"), reinterpret_cast<void*>(&rec_lines)},
    {const_cast<char*>("recClose"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&rec_close)},
    {const_cast<char*>("readerOpen"), const_cast<char*>("(Ljava/lang/String;)J"), reinterpret_cast<void*>(&reader_open)},
    {const_cast<char*>("readerRead"), const_cast<char*>("(J" PDNAV_BATCH_SIG ")I"), reinterpret_cast<void*>(&reader_read)},
    {const_cast<char*>("readerStats"), const_cast<char*>("(J)[J"), reinterpret_cast<void*>(&reader_stats)},
    {const_cast<char*>("readerProgress"), const_cast<char*>("(J)D"), reinterpret_cast<void*>(&reader_progress)},
    {const_cast<char*>("readerClose"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&reader_close)},
    {const_cast<char*>("graphPolylines"), const_cast<char*>("(Ljava/lang/String;)[D"), reinterpret_cast<void*>(&graph_polylines)},
    {const_cast<char*>("demBounds"), const_cast<char*>("(Ljava/lang/String;)[D"), reinterpret_cast<void*>(&dem_bounds)},
    {const_cast<char*>("routeOpen"), const_cast<char*>("(Ljava/lang/String;)J"), reinterpret_cast<void*>(&route_open)},
    {const_cast<char*>("routeShortest"), const_cast<char*>("(JDDDD)[D"), reinterpret_cast<void*>(&route_shortest)},
    {const_cast<char*>("routeClose"), const_cast<char*>("(J)V"), reinterpret_cast<void*>(&route_close)},
    {const_cast<char*>("geoInverse"), const_cast<char*>("(DDDD)[D"), reinterpret_cast<void*>(&geo_inverse)},
};

}  // namespace
}  // namespace pdnav::jni

extern "C" JNIEXPORT jint JNI_OnLoad(JavaVM* vm, void*) {
  JNIEnv* env = nullptr;
  if (vm->GetEnv(reinterpret_cast<void**>(&env), JNI_VERSION_1_6) != JNI_OK) return JNI_ERR;
  jclass c = env->FindClass(pdnav::jni::kBridgeClass);
  if (c == nullptr) return JNI_ERR;
  const auto n = static_cast<jint>(sizeof(pdnav::jni::kMethods) / sizeof(pdnav::jni::kMethods[0]));
  if (env->RegisterNatives(c, pdnav::jni::kMethods, n) != JNI_OK) return JNI_ERR;
  env->DeleteLocalRef(c);
  if (!pdnav::jni::load_classes(env, pdnav::jni::g_classes)) return JNI_ERR;
  return JNI_VERSION_1_6;
}
