#include "jni_support.h"

#include <ios>
#include <new>

#include "pdnav/io/log_reader.h"

namespace pdnav::jni {
namespace {

void throw_java(JNIEnv* env, const char* cls, const std::string& msg) noexcept {
  if (env->ExceptionCheck()) return;  // keep the exception the JVM already raised
  jclass c = env->FindClass(cls);
  if (c == nullptr) return;  // FindClass left NoClassDefFoundError pending
  env->ThrowNew(c, msg.c_str());
  env->DeleteLocalRef(c);
}

/// A JNI call failed and left a Java exception pending: unwind without adding another.
struct JavaPending : std::runtime_error {
  JavaPending() : std::runtime_error("Java exception pending") {}
};

void check_pending(JNIEnv* env) {
  if (env->ExceptionCheck()) throw JavaPending();
}

std::size_t array_length(JNIEnv* env, jarray a, const char* what) {
  if (a == nullptr) throw JavaError(kIllegalArgument, std::string(what) + " is null");
  return static_cast<std::size_t>(env->GetArrayLength(a));
}

void require_rows(JNIEnv* env, jarray a, const char* what, std::size_t rows, std::size_t width) {
  const std::size_t len = array_length(env, a, what);
  if (len < rows * width) {
    throw JavaError(kIllegalArgument, std::string(what) + " holds " + std::to_string(len) +
                                          " elements, " + std::to_string(rows) + " rows need " +
                                          std::to_string(rows * width));
  }
}

}  // namespace

void throw_current_as_java(JNIEnv* env) noexcept {
  try {
    throw;
  } catch (const JavaPending&) {
    // already pending
  } catch (const JavaError& e) {
    throw_java(env, e.cls, e.what());
  } catch (const io::IoError& e) {
    throw_java(env, kIo, e.what());
  } catch (const std::ios_base::failure& e) {
    throw_java(env, kIo, e.what());
  } catch (const std::invalid_argument& e) {
    throw_java(env, kIllegalArgument, e.what());
  } catch (const std::out_of_range& e) {
    throw_java(env, kIllegalArgument, e.what());
  } catch (const std::bad_alloc&) {
    throw_java(env, "java/lang/OutOfMemoryError", "native allocation failed");
  } catch (const std::exception& e) {
    throw_java(env, kRuntime, e.what());
  } catch (...) {
    throw_java(env, kRuntime, "unknown native exception");
  }
}

std::string to_string(JNIEnv* env, jstring s, const char* what) {
  if (s == nullptr) throw JavaError(kIllegalArgument, std::string(what) + " is null");
  const char* utf = env->GetStringUTFChars(s, nullptr);
  if (utf == nullptr) throw JavaPending();
  std::string out(utf);
  env->ReleaseStringUTFChars(s, utf);
  return out;
}

std::vector<std::string> to_strings(JNIEnv* env, jobjectArray a, const char* what) {
  const std::size_t n = array_length(env, a, what);
  std::vector<std::string> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    auto s = static_cast<jstring>(env->GetObjectArrayElement(a, static_cast<jsize>(i)));
    check_pending(env);
    out.push_back(to_string(env, s, what));
    env->DeleteLocalRef(s);
  }
  return out;
}

void check_batch_arrays(JNIEnv* env, std::size_t rows, const JavaBatchArrays& a) {
  require_rows(env, a.kinds, "kinds", rows, 1);
  require_rows(env, a.t_ns, "tNs", rows, 1);
  require_rows(env, a.ints, "ints", rows, kInts);
  require_rows(env, a.doubles, "doubles", rows, kDoubles);
  require_rows(env, a.strings, "strings", rows, kStrings);
  require_rows(env, a.bytes, "bytes", rows, kBytes);
}

BatchStorage::BatchStorage(std::size_t rows)
    : kinds(rows), t_ns(rows), ints(rows * kInts), doubles(rows * kDoubles), strings(rows * kStrings),
      bytes(rows * kBytes) {}

namespace {
std::size_t checked_rows(jint n) {
  if (n < 0) throw JavaError(kIllegalArgument, "negative sample count " + std::to_string(n));
  return static_cast<std::size_t>(n);
}
}  // namespace

CopiedBatch::CopiedBatch(JNIEnv* env, jint n, const JavaBatchArrays& a) : store_(checked_rows(n)) {
  const auto rows = static_cast<std::size_t>(n);
  check_batch_arrays(env, rows, a);
  BatchStorage& b = store_;
  env->GetIntArrayRegion(a.kinds, 0, n, reinterpret_cast<jint*>(b.kinds.data()));
  env->GetLongArrayRegion(a.t_ns, 0, n, reinterpret_cast<jlong*>(b.t_ns.data()));
  env->GetLongArrayRegion(a.ints, 0, static_cast<jsize>(b.ints.size()), reinterpret_cast<jlong*>(b.ints.data()));
  env->GetDoubleArrayRegion(a.doubles, 0, static_cast<jsize>(b.doubles.size()), b.doubles.data());
  env->GetByteArrayRegion(a.bytes, 0, static_cast<jsize>(b.bytes.size()), reinterpret_cast<jbyte*>(b.bytes.data()));
  check_pending(env);
  for (std::size_t i = 0; i < b.strings.size(); ++i) {
    auto s = static_cast<jstring>(env->GetObjectArrayElement(a.strings, static_cast<jsize>(i)));
    check_pending(env);
    if (s != nullptr) {  // null = empty text field
      b.strings[i] = to_string(env, s, "strings");
      env->DeleteLocalRef(s);
    }
  }
  view_ = BatchView{rows, b.kinds.data(), b.t_ns.data(), b.ints.data(), b.doubles.data(), b.strings.data(), b.bytes.data()};
}

OutBatch::OutBatch(std::size_t capacity) : store_(capacity) {
  BatchStorage& b = store_;
  out_ = BatchOut{capacity, b.kinds.data(), b.t_ns.data(), b.ints.data(), b.doubles.data(), b.strings.data(), b.bytes.data()};
}

void OutBatch::copy_to(JNIEnv* env, std::size_t n, const JavaBatchArrays& a) const {
  check_batch_arrays(env, n, a);
  const auto jn = static_cast<jsize>(n);
  const BatchStorage& b = store_;
  env->SetIntArrayRegion(a.kinds, 0, jn, reinterpret_cast<const jint*>(b.kinds.data()));
  env->SetLongArrayRegion(a.t_ns, 0, jn, reinterpret_cast<const jlong*>(b.t_ns.data()));
  env->SetLongArrayRegion(a.ints, 0, static_cast<jsize>(n * kInts), reinterpret_cast<const jlong*>(b.ints.data()));
  env->SetDoubleArrayRegion(a.doubles, 0, static_cast<jsize>(n * kDoubles), b.doubles.data());
  env->SetByteArrayRegion(a.bytes, 0, static_cast<jsize>(n * kBytes), reinterpret_cast<const jbyte*>(b.bytes.data()));
  check_pending(env);
  for (std::size_t i = 0; i < n * kStrings; ++i) {
    jstring s = env->NewStringUTF(b.strings[i].c_str());
    check_pending(env);
    env->SetObjectArrayElement(a.strings, static_cast<jsize>(i), s);
    check_pending(env);
    env->DeleteLocalRef(s);
  }
}

}  // namespace pdnav::jni
