package org.pdnav.app.nav

/**
 * The core's shortest-path router over one walkway graph (route/ behind JNI), owned like
 * [NativeNavigator]: AutoCloseable, calls serialised, closed -> IllegalStateException.
 */
class NativeRouter(graphPath: String) : AutoCloseable {
    private val h: NativeHandle
    private val registration: NativeCleaner.Registration

    init {
        NativeBridge.ensureLoaded()
        h = NativeHandle(NativeBridge.routeOpen(graphPath)) { NativeBridge.routeClose(it) }
        registration = NativeCleaner.register(this, h)
    }

    val isClosed: Boolean get() = h.isClosed

    /** The shortest walkway route, or null when the graph does not connect the two points. */
    fun shortest(fromLatDeg: Double, fromLonDeg: Double, toLatDeg: Double, toLonDeg: Double): WalkRoute? = synchronized(h) {
        WalkRoute.parse(NativeBridge.routeShortest(h.get(), fromLatDeg, fromLonDeg, toLatDeg, toLonDeg))
    }

    override fun close() {
        registration.unregister()
        h.close()
    }
}

/**
 * A route from NativeRouter: along-graph length, the straight snaps from the query points
 * to its ends, and the polyline (lat, lon in degrees).
 */
class WalkRoute(val lengthM: Double, val fromSnapM: Double, val toSnapM: Double, val points: List<DoubleArray>) {
    /** What is left to walk: to the path, along it, and from its end to the target. */
    val remainingM: Double get() = fromSnapM + lengthM + toSnapM

    companion object {
        fun parse(flat: DoubleArray): WalkRoute? {
            if (flat.size < 3) return null
            val pts = (0 until (flat.size - 3) / 2).map { k -> doubleArrayOf(flat[3 + 2 * k], flat[4 + 2 * k]) }
            return WalkRoute(flat[0], flat[1], flat[2], pts)
        }
    }
}

/** The core's geodesic inverse (WGS84): distance and initial bearing from one point to another. */
object Geo {
    data class Inverse(val distanceM: Double, val bearingRad: Double) {
        /** Bearing in degrees clockwise from north, 0..360. */
        val bearingDeg: Double get() = (Math.toDegrees(bearingRad) % 360.0 + 360.0) % 360.0
    }

    fun inverse(lat1Deg: Double, lon1Deg: Double, lat2Deg: Double, lon2Deg: Double): Inverse {
        NativeBridge.ensureLoaded()
        val r = NativeBridge.geoInverse(lat1Deg, lon1Deg, lat2Deg, lon2Deg)
        return Inverse(r[0], r[1])
    }
}
