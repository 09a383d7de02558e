package org.pdnav.app.ui

import android.content.SharedPreferences
import org.pdnav.app.nav.NavigatorConfig

/** The settings screen's values, kept in SharedPreferences; [navigatorConfig] feeds the core. */
class AppSettings(private val prefs: SharedPreferences) {
    var heightM: Double
        get() = prefs.getFloat(KEY_HEIGHT, 1.75f).toDouble()
        set(v) = prefs.edit().putFloat(KEY_HEIGHT, v.toFloat()).apply()
    var female: Boolean
        get() = prefs.getBoolean(KEY_FEMALE, false)
        set(v) = prefs.edit().putBoolean(KEY_FEMALE, v).apply()
    var particles: Int
        get() = prefs.getInt(KEY_PARTICLES, 500)
        set(v) = prefs.edit().putInt(KEY_PARTICLES, v).apply()
    /** "auto", "dr", "terrain", "route" or "gnss". */
    var engine: String
        get() = prefs.getString(KEY_ENGINE, "auto") ?: "auto"
        set(v) = prefs.edit().putString(KEY_ENGINE, v).apply()
    var startSigmaM: Double
        get() = prefs.getFloat(KEY_SIGMA, 5f).toDouble()
        set(v) = prefs.edit().putFloat(KEY_SIGMA, v.toFloat()).apply()
    /** GnssMeasurementRequest full tracking (API 31+): no duty cycling, more battery. */
    var fullTracking: Boolean
        get() = prefs.getBoolean(KEY_FULL_TRACKING, false)
        set(v) = prefs.edit().putBoolean(KEY_FULL_TRACKING, v).apply()
    var demPath: String
        get() = prefs.getString(KEY_DEM, "") ?: ""
        set(v) = prefs.edit().putString(KEY_DEM, v).apply()
    var graphPath: String
        get() = prefs.getString(KEY_GRAPH, "") ?: ""
        set(v) = prefs.edit().putString(KEY_GRAPH, v).apply()
    var basemapPath: String
        get() = prefs.getString(KEY_BASEMAP, "") ?: ""
        set(v) = prefs.edit().putString(KEY_BASEMAP, v).apply()
    /** The region last imported or navigated in: the map opens on it. */
    var lastRegion: String
        get() = prefs.getString(KEY_REGION, "") ?: ""
        set(v) = prefs.edit().putString(KEY_REGION, v).apply()
    var navPath: String
        get() = prefs.getString(KEY_NAV, "") ?: ""
        set(v) = prefs.edit().putString(KEY_NAV, v).apply()

    /**
     * The navigator's configuration. It never carries a start position: a declared start
     * belongs to one session and travels in that session's stream (Meta lines, see
     * SessionFeeder), so it is neither reused by later sessions nor forced onto a replay.
     */
    fun navigatorConfig() = NavigatorConfig(
        mode = engine,
        startSigmaM = startSigmaM,
        userHeightM = heightM,
        userFemale = female,
        demPath = demPath,
        graphPath = graphPath,
        navPaths = if (navPath.isEmpty()) emptyList() else listOf(navPath),
        particles = particles,
    )

    init {
        // Older versions kept the long-press start here and reused it for ever: drop it.
        if (prefs.contains(OLD_KEY_LAT) || prefs.contains(OLD_KEY_LON)) prefs.edit().remove(OLD_KEY_LAT).remove(OLD_KEY_LON).apply()
    }

    companion object {
        const val PREFS = "pdnav"
        const val OLD_KEY_LAT = "start_lat_deg"
        const val OLD_KEY_LON = "start_lon_deg"
        val ENGINES = listOf("auto", "dr", "terrain", "route", "gnss")
        private const val KEY_HEIGHT = "height_m"
        private const val KEY_FEMALE = "female"
        private const val KEY_PARTICLES = "particles"
        private const val KEY_ENGINE = "engine"
        private const val KEY_SIGMA = "start_sigma_m"
        private const val KEY_FULL_TRACKING = "gnss_full_tracking"
        private const val KEY_DEM = "dem_path"
        private const val KEY_GRAPH = "graph_path"
        private const val KEY_BASEMAP = "basemap_path"
        private const val KEY_NAV = "nav_path"
        private const val KEY_REGION = "last_region"
    }
}
