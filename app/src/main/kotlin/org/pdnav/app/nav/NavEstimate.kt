package org.pdnav.app.nav

import kotlin.math.atan2
import kotlin.math.sqrt

/** pdnav::EngineKind, same order (the JVM tests compare the names with the library's). */
enum class EngineKind(val label: String) {
    NONE("none"), DEAD_RECKONING("dead reckoning"), TERRAIN("terrain"), ROUTE("route"), GNSS("GNSS");
}

/** pdnav::EstimateStatus, same order. */
enum class EstimateStatus { NOT_INITIALIZED, OK, DEGRADED, AMBIGUOUS, LOST }

/**
 * pdnav::Estimate as the bridge builds it (constructor signature fixed in bridge.cpp).
 * Latitude/longitude are NaN before the first position.
 */
data class NavEstimate(
    val tNs: Long,
    val engineCode: Int,
    val statusCode: Int,
    val reason: String,
    val latDeg: Double,
    val lonDeg: Double,
    val heightM: Double,
    val eastM: Double,
    val northM: Double,
    val covEastEastM2: Double,
    val covEastNorthM2: Double,
    val covNorthNorthM2: Double,
    val verticalSigmaM: Double,
) {
    val engine: EngineKind get() = EngineKind.values().getOrElse(engineCode) { EngineKind.NONE }
    val status: EstimateStatus get() = EstimateStatus.values().getOrElse(statusCode) { EstimateStatus.LOST }
    val valid: Boolean
        get() = status == EstimateStatus.OK || status == EstimateStatus.DEGRADED || status == EstimateStatus.AMBIGUOUS

    /** Horizontal 1-sigma as DRMS, sqrt(cov_ee + cov_nn) (m). */
    val drmsM: Double get() = sqrt((covEastEastM2 + covNorthNorthM2).coerceAtLeast(0.0))

    /** 1-sigma error ellipse: semi-axes (m) and major-axis orientation clockwise from north (rad). */
    fun ellipse(): Ellipse {
        val a = covEastEastM2
        val b = covEastNorthM2
        val c = covNorthNorthM2
        val mean = 0.5 * (a + c)
        val diff = sqrt(0.25 * (a - c) * (a - c) + b * b)
        val l1 = (mean + diff).coerceAtLeast(0.0)
        val l2 = (mean - diff).coerceAtLeast(0.0)
        // major axis direction (east, north) = (l1 - c, b) or (b, l1 - a)
        val east = if (b != 0.0) b else if (a >= c) 1.0 else 0.0
        val north = if (b != 0.0) l1 - a else if (a >= c) 0.0 else 1.0
        return Ellipse(sqrt(l1), sqrt(l2), atan2(east, north))
    }

    /** The line the map shows, e.g. "GNSS · ok" or "terrain · degraded: GNSS lost, terrain engine". */
    fun statusText(): String {
        val base = "${engine.label} · ${status.name.lowercase().replace('_', ' ')}"
        return if (reason.isEmpty()) base else "$base: $reason"
    }
}

data class Ellipse(val semiMajorM: Double, val semiMinorM: Double, val orientationRad: Double)

/** pdnav::fusion::NavigatorOutput; particles as east/north pairs (m) in the engine frame. */
class NavOutput(
    val estimate: NavEstimate,
    val engines: Array<NavEstimate>,
    val steps: Long,
    val particlesEnM: DoubleArray,
)
