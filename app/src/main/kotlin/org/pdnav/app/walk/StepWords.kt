package org.pdnav.app.walk

import org.pdnav.app.nav.StepEstimate
import org.pdnav.app.nav.WalkRoute
import kotlin.math.sqrt

/** Horizontal DRMS of a step's estimate, sqrt(sigma_e^2 + sigma_n^2): the "± m" the screen shows. */
val StepEstimate.sigmaM: Double get() = sqrt(sigmaEastM * sigmaEastM + sigmaNorthM * sigmaNorthM)

/** The step has a finite position (the core sends NaN before the start is known). */
val StepEstimate.valid: Boolean get() = latDeg.isFinite() && lonDeg.isFinite()

/** What is left to walk: to the path, along it, and from its end to the place. */
val WalkRoute.remainingM: Double get() = fromSnapM + lengthM + toSnapM

/** Bearing in degrees clockwise from north, [0, 360). */
fun bearingDeg(rad: Double): Double = (Math.toDegrees(rad) % 360.0 + 360.0) % 360.0
