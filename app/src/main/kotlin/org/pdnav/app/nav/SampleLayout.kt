package org.pdnav.app.nav

/**
 * Row layout of a [SampleBatch]; mirrors core-cpp/jni/sample_codec.h (field order per kind
 * in docs/android.md). [check] compares it with the native library's at load time.
 */
object SampleLayout {
    const val VERSION = 1
    const val INTS = 16
    const val DOUBLES = 24
    const val STRINGS = 2
    const val BYTES = 64

    /** Integer "missing" marker (pdnav::kMissingInt). */
    const val MISSING = Long.MIN_VALUE

    fun check(native: IntArray) {
        val expected = intArrayOf(VERSION, INTS, DOUBLES, STRINGS, BYTES, SampleKind.COUNT)
        check(native.contentEquals(expected)) {
            "libpdnav_jni batch layout ${native.contentToString()} != Kotlin ${expected.contentToString()}"
        }
    }
}

/** Sample kinds: the index of each type in pdnav::Sample (core-cpp/include/pdnav/geo/samples.h). */
object SampleKind {
    const val ACCEL = 0
    const val GYRO = 1
    const val MAG = 2
    const val UNCAL_ACCEL = 3
    const val UNCAL_GYRO = 4
    const val UNCAL_MAG = 5
    const val ORIENTATION = 6
    const val PRESSURE = 7
    const val ROTATION_VECTOR = 8
    const val STEP_DETECTOR = 9
    const val STEP_COUNTER = 10
    const val GNSS_RAW = 11
    const val FIX = 12
    const val NAV_MESSAGE = 13
    const val GNSS_STATUS = 14
    const val AGC = 15
    const val TRUTH = 16
    const val META = 17
    const val GAME_ROTATION_VECTOR = 18
    const val SENSOR_ACCURACY = 19
    const val COUNT = 20
}
