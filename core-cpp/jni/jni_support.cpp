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
  // Not ThrowNew: it takes Modified UTF-8, and a message naming a file with an emoji would
  // abort a CheckJNI (debuggable) build. Build the message through UTF-16 instead.
  jmethodID ctor = env->GetMethodID(c, "<init>", "(Ljava/lang/String;)V");
  const std::vector<jchar> units = utf8_to_utf16(msg);
  jstring jmsg = ctor != nullptr ? env->NewString(units.data(), static_cast<jsize>(units.size())) : nullptr;
  if (jmsg != nullptr) {
    auto e = static_cast<jthrowable>(env->NewObject(c, ctor, jmsg));
    if (e != nullptr) {
      env->Throw(e);
      env->DeleteLocalRef(e);
    }
    env->DeleteLocalRef(jmsg);
  }
  env->DeleteLocalRef(c);  // on any failure above the JVM has an exception (OOM) pending
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

namespace {
constexpr std::uint32_t kReplacement = 0xFFFD;

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out.push_back(static_cast<char>(cp));
  } else if (cp < 0x800) {
    out.push_back(static_cast<char>(0xC0 | (cp >> 6)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else if (cp < 0x10000) {
    out.push_back(static_cast<char>(0xE0 | (cp >> 12)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  } else {
    out.push_back(static_cast<char>(0xF0 | (cp >> 18)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 12) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | ((cp >> 6) & 0x3F)));
    out.push_back(static_cast<char>(0x80 | (cp & 0x3F)));
  }
}

bool is_high(std::uint32_t u) { return u >= 0xD800 && u <= 0xDBFF; }
bool is_low(std::uint32_t u) { return u >= 0xDC00 && u <= 0xDFFF; }
}  // namespace

std::string utf16_to_utf8(const jchar* s, std::size_t n) {
  std::string out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t u = s[i];
    if (is_high(u) && i + 1 < n && is_low(s[i + 1])) {
      append_utf8(out, 0x10000 + ((u - 0xD800) << 10) + (static_cast<std::uint32_t>(s[i + 1]) - 0xDC00));
      ++i;
    } else if (is_high(u) || is_low(u)) {
      append_utf8(out, kReplacement);  // unpaired surrogate
    } else {
      append_utf8(out, u);
    }
  }
  return out;
}

std::vector<jchar> utf8_to_utf16(const std::string& s) {
  std::vector<jchar> out;
  out.reserve(s.size());
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const std::size_t n = s.size();
  std::size_t i = 0;
  while (i < n) {
    const unsigned char c = p[i];
    std::uint32_t cp = kReplacement;
    std::size_t len = 1;
    std::uint32_t min = 0;
    if (c < 0x80) {
      cp = c;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1F, min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0F, min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07, min = 0x10000;
    } else {
      len = 0;  // stray continuation or invalid lead byte
    }
    if (len == 0) {
      cp = kReplacement;
      len = 1;
    } else if (len > 1) {
      bool ok = i + len <= n;
      for (std::size_t k = 1; ok && k < len; ++k) {
        if ((p[i + k] & 0xC0) != 0x80) ok = false;
        else cp = (cp << 6) | (p[i + k] & 0x3F);
      }
      if (!ok || cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
        cp = kReplacement;
        len = 1;  // resynchronise on the next byte
      }
    }
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<jchar>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<jchar>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<jchar>(cp));
    }
    i += len;
  }
  return out;
}

std::string to_string(JNIEnv* env, jstring s, const char* what) {
  if (s == nullptr) throw JavaError(kIllegalArgument, std::string(what) + " is null");
  const jsize n = env->GetStringLength(s);
  std::vector<jchar> units(static_cast<std::size_t>(n));
  if (n > 0) env->GetStringRegion(s, 0, n, units.data());
  check_pending(env);
  return utf16_to_utf8(units.data(), units.size());
}

jstring new_string(JNIEnv* env, const std::string& utf8) {
  const std::vector<jchar> units = utf8_to_utf16(utf8);
  jstring s = env->NewString(units.data(), static_cast<jsize>(units.size()));
  if (s == nullptr) throw JavaPending();
  return s;
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
    jstring s = new_string(env, b.strings[i]);
    env->SetObjectArrayElement(a.strings, static_cast<jsize>(i), s);
    check_pending(env);
    env->DeleteLocalRef(s);
  }
}

}  // namespace pdnav::jni
