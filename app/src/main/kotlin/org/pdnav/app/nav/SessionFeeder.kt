package org.pdnav.app.nav

import kotlin.math.cos
import kotlin.math.hypot

/**
 * Feeds one session's sample stream into a navigator the same way live and in replay, so a
 * replay reproduces the field run:
 *  - a declared start that the session recorded after its data began (Meta
 *    `StartLatitudeDegrees`, `StartLongitudeDegrees`, `StartSigmaMeters`, in that order, at
 *    the moment of the long-press) restarts the navigator there, at that time
 *    (NativeNavigator.setStart). The header's start, before any data, is the core's own
 *    business (it starts there on the first step);
 *  - each `Truth` line (a checkpoint the tester tapped) is scored against the estimate at
 *    that moment ([checkpoints]).
 */
class SessionFeeder(val navigator: NativeNavigator) : SampleSink {
    /** One checkpoint: the known point, the estimate at its time, and the horizontal error. */
    data class Checkpoint(
        val tNs: Long, val truthLatDeg: Double, val truthLonDeg: Double,
        val estimateLatDeg: Double, val estimateLonDeg: Double, val errorM: Double, val sigmaM: Double, val engine: String,
    )

    private val scored = mutableListOf<Checkpoint>()
    private val part = SampleBatch(64)
    private var sawData = false
    private var lat = Double.NaN
    private var lon = Double.NaN

    /** Checkpoints scored so far (errorM NaN when the navigator had no position yet). */
    val checkpoints: List<Checkpoint> get() = synchronized(scored) { scored.toList() }

    /** navigator.feed calls so far (one JNI call each). */
    var feedCalls = 0L
        private set

    /** Declared starts applied after the data began. */
    var startsApplied = 0
        private set

    override fun write(batch: SampleBatch) {
        var from = 0
        for (i in 0 until batch.size) {
            when (batch.kind(i)) {
                SampleKind.META -> when (batch.string(i, 0)) {
                    KEY_LAT -> lat = batch.string(i, 1).toDoubleOrNull() ?: Double.NaN
                    KEY_LON -> lon = batch.string(i, 1).toDoubleOrNull() ?: Double.NaN
                    KEY_SIGMA -> {
                        val sigma = batch.string(i, 1).toDoubleOrNull() ?: Double.NaN
                        if (sawData && lat.isFinite() && lon.isFinite() && sigma > 0.0) {
                            feed(batch, from, i + 1)
                            from = i + 1
                            navigator.setStart(lat, lon, sigma, batch.tNs(i))
                            startsApplied++
                        }
                        lat = Double.NaN
                        lon = Double.NaN
                    }
                }
                SampleKind.TRUTH -> {
                    feed(batch, from, i + 1)
                    from = i + 1
                    score(batch.tNs(i), batch.double(i, 0), batch.double(i, 1))
                }
                else -> sawData = true
            }
        }
        feed(batch, from, batch.size)
    }

    private fun feed(b: SampleBatch, from: Int, to: Int) {
        if (from == 0 && to == b.size) {
            if (to > 0) {
                navigator.feed(b)
                feedCalls++
            }
            return
        }
        if (to <= from) return
        part.clear()
        for (i in from until to) part.addCopy(b, i)
        navigator.feed(part)
        feedCalls++
    }

    private fun score(tNs: Long, latDeg: Double, lonDeg: Double) {
        val e = navigator.estimate()
        val c = if (e.valid && e.latDeg.isFinite()) {
            Checkpoint(tNs, latDeg, lonDeg, e.latDeg, e.lonDeg, horizontalDistanceM(latDeg, lonDeg, e.latDeg, e.lonDeg),
                e.drmsM, e.engine.label)
        } else {
            Checkpoint(tNs, latDeg, lonDeg, Double.NaN, Double.NaN, Double.NaN, Double.NaN, e.engine.label)
        }
        synchronized(scored) { scored += c }
    }

    companion object {
        const val KEY_LAT = "StartLatitudeDegrees"
        const val KEY_LON = "StartLongitudeDegrees"
        const val KEY_SIGMA = "StartSigmaMeters"
        private const val EARTH_RADIUS_M = 6_371_000.0

        /** Equirectangular distance: exact to < 1 mm over the few hundred metres of a checkpoint error. */
        fun horizontalDistanceM(lat1Deg: Double, lon1Deg: Double, lat2Deg: Double, lon2Deg: Double): Double {
            val midLat = Math.toRadians(0.5 * (lat1Deg + lat2Deg))
            val dn = Math.toRadians(lat2Deg - lat1Deg) * EARTH_RADIUS_M
            val de = Math.toRadians(lon2Deg - lon1Deg) * EARTH_RADIUS_M * cos(midLat)
            return hypot(de, dn)
        }

        /** The three Meta rows of a declared start, in the order [SessionFeeder] expects. */
        fun addDeclaredStart(b: SampleBatch, tNs: Long, latDeg: Double, lonDeg: Double, sigmaM: Double) {
            b.addMeta(tNs, KEY_LAT, latDeg.toString())
            b.addMeta(tNs, KEY_LON, lonDeg.toString())
            b.addMeta(tNs, KEY_SIGMA, sigmaM.toString())
        }
    }
}
