package org.pdnav.app.nav

/**
 * route::Router on one loaded walkway graph behind a native handle ("Go to": the shortest
 * walkway path). Calls are serialised on the handle; [close] is idempotent; calls after close
 * throw IllegalStateException. A router dropped without close() is released by [NativeCleaner].
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

    /** The shortest walkway path, or null when none exists (see [NativeBridge.routeShortest]). */
    fun shortest(fromLat: Double, fromLon: Double, toLat: Double, toLon: Double): WalkRoute? = synchronized(h) {
        val a = NativeBridge.routeShortest(h.get(), fromLat, fromLon, toLat, toLon)
        if (a.isEmpty()) null
        else WalkRoute(a[0], a[1], a[2], (3 until a.size step 2).map { a[it] to a[it + 1] })
    }

    override fun close() {
        registration.unregister()
        h.close()
    }

    companion object {
        /** WGS84 geodesic distance (m) and initial bearing (rad, clockwise from true north) from 1 to 2. */
        fun geoInverse(lat1: Double, lon1: Double, lat2: Double, lon2: Double): Pair<Double, Double> {
            NativeBridge.ensureLoaded()
            val r = NativeBridge.geoInverse(lat1, lon1, lat2, lon2)
            return r[0] to r[1]
        }
    }
}

/** A walkway path: along-graph length, the straight snaps at both ends, the (lat, lon) polyline. */
data class WalkRoute(val lengthM: Double, val fromSnapM: Double, val toSnapM: Double, val points: List<Pair<Double, Double>>)
