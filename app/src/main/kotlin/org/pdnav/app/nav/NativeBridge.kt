package org.pdnav.app.nav

/**
 * The raw natives of libpdnav_jni (core-cpp/jni/bridge.cpp, registered in JNI_OnLoad).
 * Only [NativeNavigator], [NativeRecorder], [NativeLogReader] and [NativeRouter] call the
 * handle natives; they own the handles ([geoInverse] takes none). A handle of 0 (closed or never opened) makes every call throw
 * IllegalStateException; C++ exceptions arrive as IllegalArgumentException, IOException or
 * RuntimeException. Array arguments are nullable on purpose: the bridge must reject null
 * with IllegalArgumentException rather than crash, and the misuse tests check that.
 */
object NativeBridge {
    /** System property naming the library file (host JVM tests); else loadLibrary("pdnav_jni"). */
    const val LIBRARY_PROPERTY = "pdnav.jni.lib"

    init {
        val path = System.getProperty(LIBRARY_PROPERTY)
        if (path.isNullOrEmpty()) System.loadLibrary("pdnav_jni") else System.load(path)
        SampleLayout.check(layout())
    }

    /** Forces the library to load (and its layout to be checked). */
    fun ensureLoaded() = Unit

    @JvmStatic external fun layout(): IntArray
    @JvmStatic external fun engineNames(): Array<String>
    @JvmStatic external fun statusNames(): Array<String>

    @JvmStatic external fun navCreate(
        mode: String?, startLatDeg: Double, startLonDeg: Double, startSigmaM: Double,
        userHeightM: Double, userFemale: Boolean, demPath: String?, graphPath: String?,
        navPaths: Array<String>?, particles: Int, terrainPreset: String?, seed: Long,
    ): Long

    @JvmStatic external fun navFeed(
        handle: Long, n: Int, kinds: IntArray?, tNs: LongArray?, ints: LongArray?,
        doubles: DoubleArray?, strings: Array<String?>?, bytes: ByteArray?,
    )

    @JvmStatic external fun navSetStart(handle: Long, latDeg: Double, lonDeg: Double, sigmaM: Double, tNs: Long)
    @JvmStatic external fun navEstimate(handle: Long): NavEstimate
    @JvmStatic external fun navOutput(handle: Long, maxParticles: Int): NavOutput
    @JvmStatic external fun navIgnored(handle: Long): Array<String>
    /** Fused-estimate hand-overs, flat: tNs, from, to, reason, ... */
    @JvmStatic external fun navModeChanges(handle: Long): Array<String>
    /**
     * Per-step estimates since the last call (Navigator::take_steps), flattened
     * [STEP_DOUBLES] = 8 per step: `[t_ns (as double), lat_deg, lon_deg, sigma_east_m,
     * sigma_north_m, corr_en, heading_rad, distance_m]`. lat..corr_en are NaN for a step
     * before the start position is known; heading_rad is the step's walking direction
     * (calibrated, clockwise from true north, [0, 2pi)); distance_m is the distance walked
     * since the session start (sum of the calibrated step lengths). t_ns as a double is exact
     * for 104 days of elapsedRealtimeNanos.
     */
    @JvmStatic external fun navTakeSteps(handle: Long): DoubleArray
    /** End of input (Navigator::finish): releases a walk shorter than the bout gate; feed nothing after. */
    @JvmStatic external fun navFinish(handle: Long)
    @JvmStatic external fun navClose(handle: Long)

    @JvmStatic external fun recOpen(path: String?, device: String?, flushIntervalNs: Long, fsync: Boolean): Long
    @JvmStatic external fun recWrite(
        handle: Long, n: Int, kinds: IntArray?, tNs: LongArray?, ints: LongArray?,
        doubles: DoubleArray?, strings: Array<String?>?, bytes: ByteArray?,
    )
    @JvmStatic external fun recFlush(handle: Long)
    @JvmStatic external fun recLines(handle: Long): Long
    @JvmStatic external fun recClose(handle: Long)

    @JvmStatic external fun readerOpen(path: String?): Long
    @JvmStatic external fun readerRead(
        handle: Long, max: Int, kinds: IntArray?, tNs: LongArray?, ints: LongArray?,
        doubles: DoubleArray?, strings: Array<String?>?, bytes: ByteArray?,
    ): Int
    /** [lines read, samples returned, lines skipped]. */
    @JvmStatic external fun readerStats(handle: Long): LongArray
    @JvmStatic external fun readerProgress(handle: Long): Double
    @JvmStatic external fun readerClose(handle: Long)

    /** Walkway graph edges as WGS84 polylines: lat, lon pairs, each edge ended by NaN, NaN. */
    @JvmStatic external fun graphPolylines(path: String?): DoubleArray
    /** DEM tile bounds: min lat, min lon, max lat, max lon (degrees). */
    @JvmStatic external fun demBounds(path: String?): DoubleArray

    /** Loads a walkway graph for [routeShortest] (route::Router); RuntimeException "path:line: reason" on a bad file. */
    @JvmStatic external fun routeOpen(graphPath: String?): Long
    /**
     * Shortest walkway path: `[length_m, from_snap_m, to_snap_m, lat0, lon0, lat1, lon1, ...]`,
     * the polyline from the graph point nearest to `from` along walkways to the one nearest to
     * `to` (both in the connected component closest to both ends); `length_m` along the graph,
     * `*_snap_m` straight from the query points to the path's ends. Empty when no path exists
     * (no walkway within 1 km of an end in a common component). IllegalArgumentException for
     * non-finite or out-of-range input.
     */
    @JvmStatic external fun routeShortest(handle: Long, fromLat: Double, fromLon: Double, toLat: Double, toLon: Double): DoubleArray
    @JvmStatic external fun routeClose(handle: Long)

    /** WGS84 geodesic (GeographicLib): `[distance_m, initial_bearing_rad]` (clockwise from true north, [0, 2pi)). */
    @JvmStatic external fun geoInverse(lat1: Double, lon1: Double, lat2: Double, lon2: Double): DoubleArray

    /** Doubles per step in [navTakeSteps]. */
    const val STEP_DOUBLES = 8
}
