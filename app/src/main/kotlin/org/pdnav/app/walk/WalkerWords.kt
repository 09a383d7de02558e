package org.pdnav.app.walk

import org.pdnav.app.nav.EngineKind
import org.pdnav.app.nav.EstimateStatus
import org.pdnav.app.nav.NavEstimate
import org.pdnav.app.nav.NavOutput
import java.util.Locale
import kotlin.math.roundToInt

/**
 * What the main screen says to a walker, without engine jargon: how sure the position is
 * (metres and a word), where it comes from, which way they face, how far and how long they
 * have walked. Presentation only: every number comes from the core.
 */
object WalkerWords {
    /**
     * Words for a horizontal 1-sigma (DRMS) uncertainty. Bounds: a phone's open-sky GNSS fix
     * is 3-5 m (Walker, Remote Sensing 2019, Table 5: 3.95 m SPP), so <= 5 m is "very good";
     * <= 15 m still puts the walker on the right one of two paths a street apart, <= 50 m on
     * the right slope, beyond 150 m the map can only show the area.
     */
    fun quality(sigmaM: Double): String = when {
        !sigmaM.isFinite() -> "unknown"
        sigmaM <= 5.0 -> "very good"
        sigmaM <= 15.0 -> "good"
        sigmaM <= 50.0 -> "fair"
        sigmaM <= 150.0 -> "poor"
        else -> "very poor"
    }

    /** e.g. "±8 m, good"; the word is that of the number shown ("±15 m" is good, not fair). */
    fun position(sigmaM: Double): String {
        if (!sigmaM.isFinite()) return "No position yet"
        val shown = if (sigmaM < 999.5) sigmaM.roundToInt().toDouble() else sigmaM
        return "±${metres(sigmaM)}, ${quality(shown)}"
    }

    /**
     * The shown estimate's uncertainty in words ([position] of its DRMS); a position the core has
     * marked lost (the GNSS-only mode once no epoch came for 3 s) is not given its old sigma.
     */
    fun position(e: NavEstimate): String {
        if (lostWithPosition(e)) return NO_POSITION_NOW
        return position(if (e.valid && e.latDeg.isFinite()) e.drmsM else Double.NaN)
    }

    /** A position the core no longer stands by (the GNSS-only mode once no epoch came for 3 s). */
    private fun lostWithPosition(e: NavEstimate) = e.status == EstimateStatus.LOST && e.latDeg.isFinite()

    /** Where the shown position comes from, in words. [graphLoaded]: walkway graph in use. */
    fun source(out: NavOutput?, graphLoaded: Boolean): String {
        val e = out?.estimate ?: return NO_POSITION
        if (lostWithPosition(e)) return POSITION_LOST
        if (!e.valid || !e.latDeg.isFinite()) return NO_POSITION
        return when (e.engine) {
            EngineKind.GNSS -> if (e.status == EstimateStatus.OK) SATELLITES else SATELLITES_WEAK
            EngineKind.TERRAIN -> if (graphLoaded) TERRAIN_AND_PATHS else TERRAIN
            EngineKind.ROUTE -> PATHS
            EngineKind.DEAD_RECKONING -> DEAD_RECKONING
            EngineKind.NONE -> NO_POSITION
        }
    }

    private val COMPASS = listOf("north", "north-east", "east", "south-east", "south", "south-west", "west", "north-west")

    /** 8-point compass word for a bearing in degrees clockwise from north. */
    fun compass(deg: Double): String = COMPASS[(((deg % 360.0 + 360.0) % 360.0 + 22.5) / 45.0).toInt() % 8]

    /** e.g. "Facing north-east (47°)"; null without a heading. */
    fun heading(headingRad: Double): String? {
        if (!headingRad.isFinite()) return null
        val deg = (Math.toDegrees(headingRad) % 360.0 + 360.0) % 360.0
        return "Facing ${compass(deg)} (${deg.roundToInt() % 360}°)"
    }

    /** e.g. "Walked 1.24 km in 0:23:10". */
    fun walked(distanceM: Double, durationNs: Long): String {
        val d = if (distanceM.isFinite()) distanceM.coerceAtLeast(0.0) else 0.0
        val s = (durationNs / 1_000_000_000L).coerceAtLeast(0L)
        return String.format(Locale.US, "Walked %s in %d:%02d:%02d", metres(d), s / 3600, (s / 60) % 60, s % 60)
    }

    /** "8 m", "120 m", "1.24 km". */
    fun metres(m: Double): String = when {
        m < 1000.0 -> "${m.roundToInt()} m"
        else -> String.format(Locale.US, "%.2f km", m / 1000.0)
    }

    const val SATELLITES = "Satellites"
    const val SATELLITES_WEAK = "Satellites (weak signal)"
    const val TERRAIN_AND_PATHS = "No satellites: terrain and paths"
    const val TERRAIN = "No satellites: terrain"
    const val PATHS = "No satellites: paths"
    const val DEAD_RECKONING = "Dead reckoning only"
    const val NO_POSITION = "Waiting for a first position"
    const val POSITION_LOST = "Position lost: no signal"
    const val NO_POSITION_NOW = "No position now"
}
