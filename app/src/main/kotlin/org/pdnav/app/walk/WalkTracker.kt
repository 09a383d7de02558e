package org.pdnav.app.walk

import org.pdnav.app.nav.NativeRouter
import org.pdnav.app.nav.StepEstimate
import org.pdnav.app.nav.WalkRoute
import org.pdnav.app.region.Place
import org.pdnav.app.region.PlaceStore
import org.pdnav.app.region.RegionInfo
import java.text.SimpleDateFormat
import java.util.Date
import java.util.Locale

/** Go-to from the latest per-step estimate to [place] (all numbers from the core). */
data class GoTo(
    val place: Place,
    val straightM: Double,
    val bearingDeg: Double,
    /** Shortest walkway route (null: no graph, or the graph does not connect them). */
    val route: WalkRoute?,
    val sigmaM: Double,
    /** The position is too uncertain for the arrow: [sigmaM] >= [straightM] / 2 ([WalkTracker.UNCERTAIN_RATIO]). */
    val uncertain: Boolean,
    val tNs: Long,
)

/** What the walker's screen shows besides the map, after the latest step. */
data class WalkState(
    val step: StepEstimate?,
    val steps: Long,
    val distanceM: Double,
    val walkedNs: Long,
    val region: RegionInfo?,
    /** The position is outside [region]'s bounds (navigation goes on without its map data). */
    val outsideRegion: Boolean,
    val goTo: GoTo?,
    val start: Place?,
)

/**
 * Follows the navigator's per-step estimates (NativeNavigator.takeSteps) for the walker:
 * distance and time walked, the session start as a place, whether the position has left
 * the region, and Go-to: bearing and straight distance (core geodesic inverse) and the
 * shortest walkway route (core router) from every step's estimate, the route recomputed at
 * the newest step of each batch handed over (one per pump or replay batch). Runs on the
 * thread that feeds the navigator; [target] may be set from any thread.
 */
class WalkTracker(
    val region: RegionInfo?,
    private val router: NativeRouter?,
    /** Where the session start is saved (null: not saved, e.g. a replay). */
    private val places: PlaceStore?,
    private val clockMs: () -> Long = System::currentTimeMillis,
) : AutoCloseable {
    @Volatile var target: Place? = null
    private var firstNs = Long.MIN_VALUE
    private var count = 0L
    private var last: StepEstimate? = null
    private var goTo: GoTo? = null
    var start: Place? = null
        private set

    /** Routes computed (one per batch with a target), for the tests. */
    var routesComputed = 0L
        private set

    @Volatile var state: WalkState = WalkState(null, 0, 0.0, 0, region, false, null, null)
        private set

    fun onSteps(steps: List<StepEstimate>): WalkState {
        val valid = steps.filter { it.valid }
        for ((k, s) in valid.withIndex()) {
            if (firstNs == Long.MIN_VALUE) firstNs = s.tNs
            count++
            last = s
            if (start == null) saveStart(s)
            val t = target
            goTo = if (t == null) null else goTo(s, t, routeNow = k == valid.size - 1)
        }
        if (target == null) goTo = null
        val l = last
        state = WalkState(l, count, l?.distanceM ?: 0.0, if (l == null) 0 else l.tNs - firstNs, region,
            l != null && region != null && !region.bounds.contains(l.latDeg, l.lonDeg), goTo, start)
        return state
    }

    private fun saveStart(s: StepEstimate) {
        val p = Place("Start " + SimpleDateFormat("HH:mm", Locale.US).format(Date(clockMs())), s.latDeg, s.lonDeg, Place.START, clockMs())
        start = p
        places?.add(p)
    }

    private fun goTo(s: StepEstimate, t: Place, routeNow: Boolean): GoTo {
        val (distanceM, bearingRad) = NativeRouter.geoInverse(s.latDeg, s.lonDeg, t.latDeg, t.lonDeg)
        val route = if (routeNow && router != null) {
            routesComputed++
            router.shortest(s.latDeg, s.lonDeg, t.latDeg, t.lonDeg)
        } else {
            goTo?.route
        }
        val sigma = s.sigmaM
        return GoTo(t, distanceM, bearingDeg(bearingRad), route, sigma, !(sigma < UNCERTAIN_RATIO * distanceM), s.tNs)
    }

    override fun close() {
        router?.close()
    }

    companion object {
        /**
         * The arrow is withheld when sigma (DRMS) >= this x the straight distance: the 95 %
         * circle (about 1.73 x DRMS for a round error) then reaches past 0.87 of the way to the
         * place, so the true bearing may differ from the arrow by 40 degrees or more.
         */
        const val UNCERTAIN_RATIO = 0.5

        fun startName(ms: Long): String = "Start " + SimpleDateFormat("HH:mm", Locale.US).format(Date(ms))
    }
}
