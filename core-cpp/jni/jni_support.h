// JNI plumbing of the bridge: exception translation, handles, array copies.
// Thin on purpose: nothing here knows about navigation.
#pragma once
#include <jni.h>

#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sample_codec.h"

namespace pdnav::jni {

/// A Java exception to raise, by class name (thrown in C++, translated at the boundary).
struct JavaError : std::runtime_error {
  JavaError(const char* java_class, const std::string& message)
      : std::runtime_error(message), cls(java_class) {}
  const char* cls;
};

inline constexpr const char* kIllegalState = "java/lang/IllegalStateException";
inline constexpr const char* kIllegalArgument = "java/lang/IllegalArgumentException";
inline constexpr const char* kIo = "java/io/IOException";
inline constexpr const char* kRuntime = "java/lang/RuntimeException";

/// Throws the pending C++ exception as a Java exception (call inside a catch block).
void throw_current_as_java(JNIEnv* env) noexcept;

/// Runs f; any C++ exception becomes a Java exception and `fallback` is returned.
template <class R, class F>
R guarded(JNIEnv* env, R fallback, F&& f) noexcept {
  try {
    return f();
  } catch (...) {
    throw_current_as_java(env);
    return fallback;
  }
}
template <class F>
void guarded_void(JNIEnv* env, F&& f) noexcept {
  try {
    f();
  } catch (...) {
    throw_current_as_java(env);
  }
}

/// A native object owned by a Java handle; every call on it holds `mutex`.
template <class T>
struct Handle {
  template <class... A>
  explicit Handle(A&&... args) : object(std::forward<A>(args)...) {}
  std::mutex mutex;
  T object;
};

template <class T>
jlong to_handle(Handle<T>* h) { return static_cast<jlong>(reinterpret_cast<std::intptr_t>(h)); }

/// The handle's object, or IllegalStateException for a null/closed (0) handle.
template <class T>
Handle<T>& from_handle(jlong handle, const char* what) {
  if (handle == 0) throw JavaError(kIllegalState, std::string(what) + " is closed");
  return *reinterpret_cast<Handle<T>*>(static_cast<std::intptr_t>(handle));
}

/// Java string -> UTF-8 std::string; null -> IllegalArgumentException naming `what`.
/// Goes through the string's UTF-16 code units (GetStringRegion), never JNI's Modified UTF-8:
/// a supplementary character (emoji) becomes its 4-byte UTF-8 form, so a file name opens the
/// path the Kotlin side named; an unpaired surrogate becomes U+FFFD.
std::string to_string(JNIEnv* env, jstring s, const char* what);
/// UTF-8 std::string -> Java string through UTF-16 (NewString, never NewStringUTF, which
/// needs Modified UTF-8 and aborts a CheckJNI build on a 4-byte sequence). Invalid UTF-8
/// bytes become U+FFFD. Throws JavaPending when the allocation failed.
jstring new_string(JNIEnv* env, const std::string& utf8);

/// Standard UTF-8 <-> UTF-16 conversions (replacement character for invalid input).
std::string utf16_to_utf8(const jchar* s, std::size_t n);
std::vector<jchar> utf8_to_utf16(const std::string& s);
/// Java String[] -> vector; null array or element -> IllegalArgumentException.
std::vector<std::string> to_strings(JNIEnv* env, jobjectArray a, const char* what);

/// The Java arrays of a SampleBatch (Kotlin SampleBatch fields, in this order).
struct JavaBatchArrays {
  jintArray kinds;
  jlongArray t_ns;
  jlongArray ints;
  jdoubleArray doubles;
  jobjectArray strings;
  jbyteArray bytes;
};

/// The fixed-width columns of `rows` batch rows (sample_codec.h layout).
struct BatchStorage {
  explicit BatchStorage(std::size_t rows);
  std::vector<std::int32_t> kinds;
  std::vector<std::int64_t> t_ns;
  std::vector<std::int64_t> ints;
  std::vector<double> doubles;
  std::vector<std::string> strings;
  std::vector<std::int8_t> bytes;
};

/// n rows copied out of Java arrays (validated: non-null, long enough).
class CopiedBatch {
 public:
  CopiedBatch(JNIEnv* env, jint n, const JavaBatchArrays& a);
  const BatchView& view() const { return view_; }

 private:
  BatchStorage store_;
  BatchView view_;
};

/// Rows built natively, then copied into Java arrays (validated capacity >= rows).
class OutBatch {
 public:
  explicit OutBatch(std::size_t capacity);
  BatchOut& rows() { return out_; }
  /// Copies the first n rows into the Java arrays.
  void copy_to(JNIEnv* env, std::size_t n, const JavaBatchArrays& a) const;

 private:
  BatchStorage store_;
  BatchOut out_;
};

/// Checks that every array is non-null and holds at least `rows` rows.
void check_batch_arrays(JNIEnv* env, std::size_t rows, const JavaBatchArrays& a);

}  // namespace pdnav::jni
