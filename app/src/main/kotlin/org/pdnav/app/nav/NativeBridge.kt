package org.pdnav.app.nav

/**
 * The raw natives of libpdnav_jni (core-cpp/jni/bridge.cpp, registered in JNI_OnLoad).
 * Only [NativeNavigator], [NativeRecorder] and [NativeLogReader] call these; they own the
 * handles. A handle of 0 (closed or never opened) makes every call throw
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

    // ---- issue 29 (interface-29.md): routing, per-step estimates, finish, geodesic inverse ----
    /** A loaded walkway graph + shortest-path router (owned by [NativeRouter]). */
    @JvmStatic external fun routeOpen(graphPath: String?): Long
    @JvmStatic external fun routeClose(handle: Long)
    /**
     * Shortest walkway path: [length_m, from_snap_m, to_snap_m, lat0, lon0, lat1, lon1, ...];
     * empty when no path exists; IllegalArgumentException for non-finite input.
     */
    @JvmStatic external fun routeShortest(handle: Long, fromLat: Double, fromLon: Double, toLat: Double, toLon: Double): DoubleArray
    /**
     * Per-step estimates since the last call, 8 per step: t_ns (as double), lat, lon,
     * sigma_east_m, sigma_north_m, corr_en, heading_rad, distance_m.
     */
    @JvmStatic external fun navTakeSteps(handle: Long): DoubleArray
    /** Navigator::finish(): end of input (releases short walks, final estimate). */
    @JvmStatic external fun navFinish(handle: Long)
    /** Geodesic inverse on WGS84: [distance_m, initial_bearing_rad]. */
    @JvmStatic external fun geoInverse(lat1: Double, lon1: Double, lat2: Double, lon2: Double): DoubleArray
}
