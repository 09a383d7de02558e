package org.pdnav.app.nav

import org.pdnav.app.nav.SampleLayout.MISSING

/**
 * One GnssMeasurement with its GnssClock (GnssLogger `Raw` line), field for field as
 * pdnav::GnssRawSample. Missing integers are [SampleLayout.MISSING], missing reals NaN.
 * [ints]/[doubles] give the GNSS_RAW row order of core-cpp/jni/sample_codec.cpp.
 */
data class GnssRawRow(
    val utcMs: Long = MISSING,
    val timeNanos: Long = MISSING,
    val leapSecond: Long = MISSING,
    val fullBiasNanos: Long = MISSING,
    val hardwareClockDiscontinuityCount: Long = MISSING,
    val svid: Long = 0,
    val state: Long = 0,
    val receivedSvTimeNanos: Long = MISSING,
    val receivedSvTimeUncertaintyNanos: Long = MISSING,
    val accumulatedDeltaRangeState: Long = 0,
    val carrierCycles: Long = MISSING,
    val multipathIndicator: Long = 0,
    val constellationType: Long = 0,
    val chipsetElapsedRealtimeNanos: Long = MISSING,
    val timeUncertaintyNanos: Double = Double.NaN,
    val biasNanos: Double = Double.NaN,
    val biasUncertaintyNanos: Double = Double.NaN,
    val driftNanosPerSecond: Double = Double.NaN,
    val driftUncertaintyNanosPerSecond: Double = Double.NaN,
    val timeOffsetNanos: Double = Double.NaN,
    val cn0DbHz: Double = Double.NaN,
    val pseudorangeRateMps: Double = Double.NaN,
    val pseudorangeRateUncertaintyMps: Double = Double.NaN,
    val accumulatedDeltaRangeM: Double = Double.NaN,
    val accumulatedDeltaRangeUncertaintyM: Double = Double.NaN,
    val carrierFrequencyHz: Double = Double.NaN,
    val carrierPhase: Double = Double.NaN,
    val carrierPhaseUncertainty: Double = Double.NaN,
    val snrDb: Double = Double.NaN,
    val agcDb: Double = Double.NaN,
    val basebandCn0DbHz: Double = Double.NaN,
    val fullInterSignalBiasNanos: Double = Double.NaN,
    val fullInterSignalBiasUncertaintyNanos: Double = Double.NaN,
    val satelliteInterSignalBiasNanos: Double = Double.NaN,
    val satelliteInterSignalBiasUncertaintyNanos: Double = Double.NaN,
    val codeType: String = "",
) {
    fun ints() = longArrayOf(utcMs, timeNanos, leapSecond, fullBiasNanos,
        hardwareClockDiscontinuityCount, svid, state, receivedSvTimeNanos,
        receivedSvTimeUncertaintyNanos, accumulatedDeltaRangeState, carrierCycles,
        multipathIndicator, constellationType, chipsetElapsedRealtimeNanos)

    fun doubles() = doubleArrayOf(timeUncertaintyNanos, biasNanos, biasUncertaintyNanos,
        driftNanosPerSecond, driftUncertaintyNanosPerSecond, timeOffsetNanos, cn0DbHz,
        pseudorangeRateMps, pseudorangeRateUncertaintyMps, accumulatedDeltaRangeM,
        accumulatedDeltaRangeUncertaintyM, carrierFrequencyHz, carrierPhase,
        carrierPhaseUncertainty, snrDb, agcDb, basebandCn0DbHz, fullInterSignalBiasNanos,
        fullInterSignalBiasUncertaintyNanos, satelliteInterSignalBiasNanos,
        satelliteInterSignalBiasUncertaintyNanos)

    companion object {
        const val N_INTS = 14
        const val N_DOUBLES = 21

        fun fromRow(i: LongArray, d: DoubleArray, codeType: String) = GnssRawRow(
            i[0], i[1], i[2], i[3], i[4], i[5], i[6], i[7], i[8], i[9], i[10], i[11], i[12], i[13],
            d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7], d[8], d[9], d[10], d[11], d[12], d[13],
            d[14], d[15], d[16], d[17], d[18], d[19], d[20], codeType,
        )
    }
}
