package org.pdnav.app.nav

import org.junit.Test
import java.io.File
import kotlin.math.abs
import kotlin.test.assertEquals
import kotlin.test.assertTrue

/**
 * Kotlin rows -> NativeRecorder (io::LogWriter) -> file -> NativeLogReader (io::LogReader)
 * -> Kotlin rows: every field of every kind the app records survives, and the text columns
 * carry the values under the right names (so the two codec directions cannot both be wrong).
 */
class RecorderRoundTripTest {
    private val raw = GnssRawRow(
        utcMs = 1_700_000_000_123L, timeNanos = 123_456_789_000L, leapSecond = 18, fullBiasNanos = -1_384_000_000_123_456_789L,
        hardwareClockDiscontinuityCount = 2, svid = 23, state = 16431, receivedSvTimeNanos = 345_678_901_234L,
        receivedSvTimeUncertaintyNanos = 12, accumulatedDeltaRangeState = 17, carrierCycles = 5,
        multipathIndicator = 0, constellationType = 1, chipsetElapsedRealtimeNanos = 9_876_543_210L,
        timeUncertaintyNanos = 0.5, biasNanos = 0.25, biasUncertaintyNanos = 31.5, driftNanosPerSecond = -1.125,
        driftUncertaintyNanosPerSecond = 2.5, timeOffsetNanos = 0.0, cn0DbHz = 37.3, pseudorangeRateMps = -512.25,
        pseudorangeRateUncertaintyMps = 0.07, accumulatedDeltaRangeM = 1234.5678, accumulatedDeltaRangeUncertaintyM = 0.003,
        carrierFrequencyHz = 1.57542e9, carrierPhase = 0.4, carrierPhaseUncertainty = 0.01, snrDb = 41.0, agcDb = 3.5,
        basebandCn0DbHz = 33.1, fullInterSignalBiasNanos = 5.5, fullInterSignalBiasUncertaintyNanos = 0.75,
        satelliteInterSignalBiasNanos = -2.25, satelliteInterSignalBiasUncertaintyNanos = 0.5, codeType = "C",
    )
    private val fix = FixRow(1_700_000_000_500L, "GPS", 37.422578, -122.081678, -28.5, 1.25, 3.9, 270.5, 0.5, 12.0, 4.5)
    private val navData = ByteArray(40) { (it * 7 - 100).toByte() }

    private fun allKinds(t0: Long) = SampleBatch().apply {
        addMeta(t0, "UserHeightMeters", "1.82")
        addVector(SampleKind.ACCEL, t0 + 1, 0.125, -9.80665, 1.5e-3)
        addVector(SampleKind.GYRO, t0 + 2, 1e-4, -0.25, 3.0)
        addVector(SampleKind.MAG, t0 + 3, 22.5, -5.0, -40.75)
        addPressure(t0 + 4, 95_432.1)
        addRotationVector(t0 + 5, 0.1, 0.2, 0.3, 0.927362, 0.05)
        addStep(t0 + 6)
        addGnssRaw(t0 + 7, raw)
        addFix(t0 + 8, fix)
        addNavMessage(t0 + 9, 23, 0x0101, 1, 3, 2, navData)
        addUncalibrated(SampleKind.UNCAL_GYRO, t0 + 10, doubleArrayOf(0.01, 0.02, 0.03), doubleArrayOf(1e-3, 2e-3, 3e-3))
        addGameRotationVector(t0 + 11, -0.5, 0.25, 0.125, 0.8196798, utcMs = 1_700_000_000_777L)
        addSensorAccuracy(t0 + 12, 2, 1, utcMs = 1_700_000_000_778L)  // TYPE_MAGNETIC_FIELD, SENSOR_STATUS_ACCURACY_LOW
    }

    @Test
    fun everyFieldSurvivesWriteAndRead() {
        val file = TestPaths.scratch("roundtrip").resolve("all.txt")
        val t0 = 5_000_000_000L
        val written = allKinds(t0)
        NativeRecorder(file.path, "test device").use { it.write(written) }
        val back = SampleBatch()
        NativeLogReader(file.path).use { r ->
            assertTrue(r.read(back, 100))
            assertEquals(0L, r.stats.skipped)
        }
        assertEquals(written.size, back.size)
        for (i in 0 until written.size) {
            assertEquals(written.kind(i), back.kind(i), "kind of row $i")
            assertEquals(written.tNs(i), back.tNs(i), "time of row $i")
        }
        assertEquals("UserHeightMeters", back.string(0, 0)); assertEquals("1.82", back.string(0, 1))
        for ((row, n) in listOf(1 to 3, 2 to 3, 3 to 3, 5 to 5, 10 to 6, 11 to 4)) {
            for (k in 0 until n) assertEquals(written.double(row, k), back.double(row, k), "row $row value $k")
        }
        assertTrue(abs(back.double(4, 0) - 95_432.1) < 1e-6, "pressure (Pa, stored in hPa): ${back.double(4, 0)}")
        assertEquals(raw, back.gnssRaw(7))
        assertEquals(fix, back.fix(8))
        assertEquals(navData.toList(), back.navData(9).toList())
        for (k in 0..4) assertEquals(written.long(9, k), back.long(9, k), "nav field $k")
        assertEquals(1_700_000_000_777L, back.long(11, 0), "game rotation vector UTC")
        for (k in 0..2) assertEquals(written.long(12, k), back.long(12, k), "sensor accuracy field $k")
    }

    @Test
    fun textColumnsCarryTheValuesUnderTheirNames() {
        val file = TestPaths.scratch("columns").resolve("cols.txt")
        NativeRecorder(file.path).use { it.write(allKinds(1_000L)) }
        assertEquals("23", column(file, "Raw", "Svid"))
        assertEquals(37.3, column(file, "Raw", "Cn0DbHz").toDouble())
        assertEquals(-512.25, column(file, "Raw", "PseudorangeRateMetersPerSecond").toDouble())
        assertEquals(raw.fullBiasNanos, column(file, "Raw", "FullBiasNanos").toLong())
        assertEquals(raw.receivedSvTimeNanos, column(file, "Raw", "ReceivedSvTimeNanos").toLong())
        assertEquals("C", column(file, "Raw", "CodeType"))
        assertEquals(37.422578, column(file, "Fix", "LatitudeDegrees").toDouble())
        assertEquals(-122.081678, column(file, "Fix", "LongitudeDegrees").toDouble())
        assertEquals(-9.80665, column(file, "Accel", "AccelYMps2").toDouble())
        assertEquals(-0.5, column(file, "GameRotationVector", "QuatX").toDouble())
        assertEquals(0.8196798, column(file, "GameRotationVector", "QuatW").toDouble())
        assertEquals("2", column(file, "SensorAccuracy", "SensorType"))
        assertEquals("1", column(file, "SensorAccuracy", "Accuracy"))
    }

    @Test
    fun sensorAccuracyOutsideAndroidsValuesIsRefusedBeforeTheLog() {
        val b = SampleBatch()
        kotlin.test.assertFailsWith<IllegalArgumentException> { b.addSensorAccuracy(1L, 2, 4) }
        kotlin.test.assertFailsWith<IllegalArgumentException> { b.addSensorAccuracy(1L, 0, 3) }
        assertEquals(0, b.size)
    }

    @Test
    fun aKilledRecorderLosesAtMostTheLastSecond() {
        val file = TestPaths.scratch("crash").resolve("crash.txt")
        val rec = NativeRecorder(file.path, flushIntervalNs = 1_000_000_000L)
        val t0 = 10_000_000_000L
        val b = SampleBatch()
        var lastT = 0L
        for (k in 0 until 55) {  // 5.5 s of 100 Hz accelerometer, in 100 ms batches
            b.clear()
            for (r in 0 until 10) {
                lastT = t0 + (k * 10 + r) * 10_000_000L
                b.addVector(SampleKind.ACCEL, lastT, r.toDouble(), 0.0, 9.81)
            }
            rec.write(b)
        }
        // "kill": read what reached the OS without flush() or close()
        val text = file.readText()
        assertTrue(text.isEmpty() || text.endsWith("\n"), "no torn line")
        var seenT = Long.MIN_VALUE
        NativeLogReader(file.path).use { r ->
            val back = SampleBatch()
            while (r.read(back, 1000)) for (i in 0 until back.size) seenT = maxOf(seenT, back.tNs(i))
            assertEquals(0L, r.stats.skipped)
        }
        assertTrue(lastT - seenT <= 1_000_000_000L, "lost ${(lastT - seenT) / 1e6} ms of samples (> 1 s)")
        rec.close()
    }

    /** Value of [name] on the first [type] line, by the header comment's column list. */
    private fun column(file: File, type: String, name: String): String {
        val lines = file.readLines()
        val header = lines.first { it.startsWith("#") && it.removePrefix("#").trim().startsWith("$type,") }
            .removePrefix("#").trim().split(',')
        val row = lines.first { it.startsWith("$type,") }.split(',')
        val k = header.indexOf(name)
        assertTrue(k > 0, "column $name in $header")
        return row[k]
    }
}
