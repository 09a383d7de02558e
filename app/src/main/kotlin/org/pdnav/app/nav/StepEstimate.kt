package org.pdnav.app.nav

import kotlin.math.sqrt

/**
 * One per-step estimate of the navigator (NativeBridge.navTakeSteps, 8 doubles per step):
 * position, its 1-sigma east/north deviations and correlation, heading (rad, clockwise from
 * north) and the distance walked so far (m).
 */
data class StepEstimate(
    val tNs: Long,
    val latDeg: Double,
    val lonDeg: Double,
    val sigmaEastM: Double,
    val sigmaNorthM: Double,
    val corrEn: Double,
    val headingRad: Double,
    val distanceM: Double,
) {
    /** Horizontal DRMS, sqrt(sigma_e^2 + sigma_n^2): the "± m" the screen shows. */
    val sigmaM: Double get() = sqrt(sigmaEastM * sigmaEastM + sigmaNorthM * sigmaNorthM)
    val valid: Boolean get() = latDeg.isFinite() && lonDeg.isFinite()

    companion object {
        const val STRIDE = 8

        fun parse(flat: DoubleArray): List<StepEstimate> {
            require(flat.size % STRIDE == 0) { "step array of ${flat.size} values is not a multiple of $STRIDE" }
            return (0 until flat.size / STRIDE).map { k ->
                val o = k * STRIDE
                StepEstimate(flat[o].toLong(), flat[o + 1], flat[o + 2], flat[o + 3], flat[o + 4], flat[o + 5], flat[o + 6], flat[o + 7])
            }
        }
    }
}
