package org.pdnav.app.nav

import org.pdnav.app.nav.SampleLayout.BYTES
import org.pdnav.app.nav.SampleLayout.DOUBLES
import org.pdnav.app.nav.SampleLayout.INTS
import org.pdnav.app.nav.SampleLayout.MISSING
import org.pdnav.app.nav.SampleLayout.STRINGS

/**
 * A growable batch of time-stamped samples as fixed-width primitive arrays (one row per
 * sample, layout in [SampleLayout]); the unit that crosses JNI in one call. Values are in
 * the core's units (m/s^2, rad/s, uT, Pa, degrees, m); every time is elapsedRealtimeNanos.
 * Not thread-safe: one producer fills it, then hands it to a [SampleSink].
 */
class SampleBatch(initialCapacity: Int = 256) {
    var size = 0
        private set
    var kinds = IntArray(initialCapacity)
        private set
    var tNs = LongArray(initialCapacity)
        private set
    var ints = LongArray(initialCapacity * INTS)
        private set
    var doubles = DoubleArray(initialCapacity * DOUBLES)
        private set
    var strings = arrayOfNulls<String>(initialCapacity * STRINGS)
        private set
    var bytes = ByteArray(initialCapacity * BYTES)
        private set

    val capacity: Int get() = kinds.size

    fun clear() {
        size = 0
    }

    /** Grows the arrays to hold at least [n] rows (keeps the rows already there). */
    fun ensureCapacity(n: Int) {
        if (n <= capacity) return
        val c = maxOf(n, capacity * 2, 16)
        kinds = kinds.copyOf(c)
        tNs = tNs.copyOf(c)
        ints = ints.copyOf(c * INTS)
        doubles = doubles.copyOf(c * DOUBLES)
        strings = strings.copyOf(c * STRINGS)
        bytes = bytes.copyOf(c * BYTES)
    }

    /** Sets the row count after a native call filled the arrays (NativeLogReader). */
    internal fun setFilled(n: Int) {
        require(n in 0..capacity) { "row count $n outside 0..$capacity" }
        size = n
    }

    // ---- reading rows --------------------------------------------------------------------
    fun kind(i: Int): Int = kinds[checkRow(i)]
    fun tNs(i: Int): Long = tNs[checkRow(i)]
    fun long(i: Int, k: Int): Long = ints[checkRow(i) * INTS + k]
    fun double(i: Int, k: Int): Double = doubles[checkRow(i) * DOUBLES + k]
    fun string(i: Int, k: Int): String = strings[checkRow(i) * STRINGS + k] ?: ""
    fun navData(i: Int): ByteArray {
        val n = long(i, NAV_LENGTH).toInt()
        return bytes.copyOfRange(i * BYTES, i * BYTES + n)
    }

    private fun checkRow(i: Int): Int {
        if (i !in 0 until size) throw IndexOutOfBoundsException("row $i of $size")
        return i
    }

    // ---- adding rows ---------------------------------------------------------------------
    /** Starts a new row with every field missing; returns its index. */
    fun addRow(kind: Int, t: Long): Int {
        require(kind in 0 until SampleKind.COUNT) { "unknown sample kind $kind" }
        ensureCapacity(size + 1)
        val r = size++
        kinds[r] = kind
        tNs[r] = t
        ints.fill(MISSING, r * INTS, (r + 1) * INTS)
        doubles.fill(Double.NaN, r * DOUBLES, (r + 1) * DOUBLES)
        strings.fill(null, r * STRINGS, (r + 1) * STRINGS)
        bytes.fill(0, r * BYTES, (r + 1) * BYTES)
        return r
    }

    fun setLong(r: Int, k: Int, v: Long) { ints[r * INTS + k] = v }
    fun setDouble(r: Int, k: Int, v: Double) { doubles[r * DOUBLES + k] = v }
    fun setString(r: Int, k: Int, v: String) { strings[r * STRINGS + k] = v }

    /** Accelerometer / gyroscope / magnetometer (kind ACCEL, GYRO or MAG). */
    fun addVector(kind: Int, t: Long, x: Double, y: Double, z: Double, utcMs: Long = MISSING) {
        require(kind == SampleKind.ACCEL || kind == SampleKind.GYRO || kind == SampleKind.MAG) { "not a vector kind: $kind" }
        val r = addRow(kind, t)
        setLong(r, 0, utcMs)
        setDouble(r, 0, x); setDouble(r, 1, y); setDouble(r, 2, z)
    }

    /** Uncalibrated sensor with its bias (kind UNCAL_ACCEL, UNCAL_GYRO or UNCAL_MAG). */
    fun addUncalibrated(kind: Int, t: Long, v: DoubleArray, bias: DoubleArray, utcMs: Long = MISSING) {
        require(kind == SampleKind.UNCAL_ACCEL || kind == SampleKind.UNCAL_GYRO || kind == SampleKind.UNCAL_MAG) { "not an uncalibrated kind: $kind" }
        require(v.size == 3 && bias.size == 3) { "uncalibrated sample needs 3 values and 3 biases" }
        val r = addRow(kind, t)
        setLong(r, 0, utcMs)
        for (k in 0..2) { setDouble(r, k, v[k]); setDouble(r, 3 + k, bias[k]) }
    }

    fun addPressure(t: Long, pressurePa: Double, utcMs: Long = MISSING) {
        val r = addRow(SampleKind.PRESSURE, t)
        setLong(r, 0, utcMs)
        setDouble(r, 0, pressurePa)
    }

    /** Unit quaternion phone->ENU (x, y, z, w) and heading accuracy (NaN if unknown). */
    fun addRotationVector(t: Long, x: Double, y: Double, z: Double, w: Double, headingAccuracyRad: Double, utcMs: Long = MISSING) {
        val r = addRow(SampleKind.ROTATION_VECTOR, t)
        setLong(r, 0, utcMs)
        setDouble(r, 0, x); setDouble(r, 1, y); setDouble(r, 2, z); setDouble(r, 3, w)
        setDouble(r, 4, headingAccuracyRad)
    }

    /** Game rotation vector: unit quaternion phone->(Z up, arbitrary yaw) frame, no magnetometer. */
    fun addGameRotationVector(t: Long, x: Double, y: Double, z: Double, w: Double, utcMs: Long = MISSING) {
        val r = addRow(SampleKind.GAME_ROTATION_VECTOR, t)
        setLong(r, 0, utcMs)
        setDouble(r, 0, x); setDouble(r, 1, y); setDouble(r, 2, z); setDouble(r, 3, w)
    }

    /**
     * onAccuracyChanged: Android sensor type and SENSOR_STATUS_* (-1 no contact .. 3 high);
     * the log reader rejects other values, so they are refused here already.
     */
    fun addSensorAccuracy(t: Long, sensorType: Int, accuracy: Int, utcMs: Long = MISSING) {
        require(sensorType > 0) { "sensor type $sensorType is not an Android sensor type" }
        require(accuracy in -1..3) { "accuracy $accuracy is not a SENSOR_STATUS (-1..3)" }
        val r = addRow(SampleKind.SENSOR_ACCURACY, t)
        setLong(r, 0, utcMs); setLong(r, 1, sensorType.toLong()); setLong(r, 2, accuracy.toLong())
    }

    fun addStep(t: Long, utcMs: Long = MISSING) {
        val r = addRow(SampleKind.STEP_DETECTOR, t)
        setLong(r, 0, utcMs)
    }

    fun addGnssRaw(t: Long, m: GnssRawRow) {
        val r = addRow(SampleKind.GNSS_RAW, t)
        m.ints().forEachIndexed { k, v -> setLong(r, k, v) }
        m.doubles().forEachIndexed { k, v -> setDouble(r, k, v) }
        setString(r, 0, m.codeType)
    }

    fun gnssRaw(i: Int): GnssRawRow {
        require(kind(i) == SampleKind.GNSS_RAW) { "row $i is kind ${kind(i)}, not GNSS_RAW" }
        return GnssRawRow.fromRow(LongArray(GnssRawRow.N_INTS) { long(i, it) },
            DoubleArray(GnssRawRow.N_DOUBLES) { double(i, it) }, string(i, 0))
    }

    fun addFix(t: Long, fix: FixRow) {
        val r = addRow(SampleKind.FIX, t)
        setLong(r, 0, fix.utcMs)
        setString(r, 0, fix.provider)
        fix.doubles().forEachIndexed { k, v -> setDouble(r, k, v) }
    }

    fun fix(i: Int): FixRow {
        require(kind(i) == SampleKind.FIX) { "row $i is kind ${kind(i)}, not FIX" }
        return FixRow.fromRow(long(i, 0), string(i, 0), DoubleArray(FixRow.N_DOUBLES) { double(i, it) })
    }

    /** GnssNavigationMessage: data of at most [SampleLayout.BYTES] bytes. */
    fun addNavMessage(t: Long, svid: Int, type: Int, status: Int, messageId: Int, subMessageId: Int, data: ByteArray) {
        require(data.size <= BYTES) { "navigation message of ${data.size} bytes exceeds $BYTES" }
        val r = addRow(SampleKind.NAV_MESSAGE, t)
        setLong(r, 0, svid.toLong()); setLong(r, 1, type.toLong()); setLong(r, 2, status.toLong())
        setLong(r, 3, messageId.toLong()); setLong(r, 4, subMessageId.toLong())
        setLong(r, NAV_LENGTH, data.size.toLong())
        data.copyInto(bytes, r * BYTES)
    }

    /** One satellite of a GnssStatus callback (GnssLogger `Status` line). */
    fun addStatus(t: Long, utcMs: Long, count: Int, index: Int, constellation: Int, svid: Int, used: Boolean,
                  almanac: Boolean, ephemeris: Boolean, carrierHz: Double, cn0DbHz: Double, azimuthDeg: Double,
                  elevationDeg: Double, basebandCn0DbHz: Double) {
        val r = addRow(SampleKind.GNSS_STATUS, t)
        setLong(r, 0, utcMs); setLong(r, 1, count.toLong()); setLong(r, 2, index.toLong())
        setLong(r, 3, constellation.toLong()); setLong(r, 4, svid.toLong())
        setLong(r, 5, if (used) 1 else 0); setLong(r, 6, if (almanac) 1 else 0); setLong(r, 7, if (ephemeris) 1 else 0)
        setDouble(r, 0, carrierHz); setDouble(r, 1, cn0DbHz); setDouble(r, 2, azimuthDeg); setDouble(r, 3, elevationDeg)
        setDouble(r, 4, basebandCn0DbHz)
    }

    /** Automatic gain control of one band (GnssLogger `Agc` line, API 33+). */
    fun addAgc(t: Long, utcMs: Long, timeNanos: Long, constellation: Int, agcDb: Double, carrierHz: Double) {
        val r = addRow(SampleKind.AGC, t)
        setLong(r, 0, utcMs); setLong(r, 1, timeNanos); setLong(r, 2, constellation.toLong())
        setDouble(r, 0, agcDb); setDouble(r, 1, carrierHz)
    }

    /** A known position (checkpoint) at time t: the `Truth` line replay scores against. */
    fun addTruth(t: Long, latDeg: Double, lonDeg: Double, heightM: Double = Double.NaN, headingDeg: Double = Double.NaN) {
        val r = addRow(SampleKind.TRUTH, t)
        setDouble(r, 0, latDeg); setDouble(r, 1, lonDeg); setDouble(r, 2, heightM); setDouble(r, 3, headingDeg)
    }

    fun addMeta(t: Long, key: String, value: String) {
        val r = addRow(SampleKind.META, t)
        setString(r, 0, key)
        setString(r, 1, value)
    }

    /** Appends row [i] of [other]. */
    fun addCopy(other: SampleBatch, i: Int) {
        other.checkRow(i)
        ensureCapacity(size + 1)
        val r = size++
        kinds[r] = other.kinds[i]
        tNs[r] = other.tNs[i]
        other.ints.copyInto(ints, r * INTS, i * INTS, (i + 1) * INTS)
        other.doubles.copyInto(doubles, r * DOUBLES, i * DOUBLES, (i + 1) * DOUBLES)
        other.strings.copyInto(strings, r * STRINGS, i * STRINGS, (i + 1) * STRINGS)
        other.bytes.copyInto(bytes, r * BYTES, i * BYTES, (i + 1) * BYTES)
    }

    /** Indices of the rows in time order (stable: equal times keep their order). */
    fun timeOrder(): IntArray = (0 until size).sortedWith(compareBy { tNs[it] }).toIntArray()

    companion object {
        /** ints slot holding a navigation message's data length. */
        const val NAV_LENGTH = 5
    }
}

/** A position fix (Android Location), in the order of the FIX row's doubles. */
data class FixRow(
    val utcMs: Long, val provider: String, val latDeg: Double, val lonDeg: Double,
    val altM: Double = Double.NaN, val speedMps: Double = Double.NaN, val accuracyM: Double = Double.NaN,
    val bearingDeg: Double = Double.NaN, val speedAccuracyMps: Double = Double.NaN,
    val bearingAccuracyDeg: Double = Double.NaN, val verticalAccuracyM: Double = Double.NaN,
) {
    fun doubles() = doubleArrayOf(latDeg, lonDeg, altM, speedMps, accuracyM, bearingDeg,
        speedAccuracyMps, bearingAccuracyDeg, verticalAccuracyM)

    companion object {
        const val N_DOUBLES = 9
        fun fromRow(utcMs: Long, provider: String, d: DoubleArray) =
            FixRow(utcMs, provider, d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8])
    }
}
