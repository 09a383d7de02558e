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
    /** Declared start (long-press on the map); NaN = use the first GNSS fix. */
    var startLatDeg: Double
        get() = java.lang.Double.longBitsToDouble(prefs.getLong(KEY_LAT, NAN_BITS))
        set(v) = prefs.edit().putLong(KEY_LAT, java.lang.Double.doubleToRawLongBits(v)).apply()
    var startLonDeg: Double
        get() = java.lang.Double.longBitsToDouble(prefs.getLong(KEY_LON, NAN_BITS))
        set(v) = prefs.edit().putLong(KEY_LON, java.lang.Double.doubleToRawLongBits(v)).apply()
    var demPath: String
        get() = prefs.getString(KEY_DEM, "") ?: ""
        set(v) = prefs.edit().putString(KEY_DEM, v).apply()
    var graphPath: String
        get() = prefs.getString(KEY_GRAPH, "") ?: ""
        set(v) = prefs.edit().putString(KEY_GRAPH, v).apply()
    var basemapPath: String
        get() = prefs.getString(KEY_BASEMAP, "") ?: ""
        set(v) = prefs.edit().putString(KEY_BASEMAP, v).apply()
    var navPath: String
        get() = prefs.getString(KEY_NAV, "") ?: ""
        set(v) = prefs.edit().putString(KEY_NAV, v).apply()

    /** Start at the last GNSS fix instead of a declared point. */
    fun useLastFix() {
        startLatDeg = Double.NaN
        startLonDeg = Double.NaN
    }

    fun navigatorConfig() = NavigatorConfig(
        mode = engine,
        startLatDeg = startLatDeg,
        startLonDeg = startLonDeg,
        startSigmaM = startSigmaM,
        userHeightM = heightM,
        userFemale = female,
        demPath = demPath,
        graphPath = graphPath,
        navPaths = if (navPath.isEmpty()) emptyList() else listOf(navPath),
        particles = particles,
    )

    companion object {
        const val PREFS = "pdnav"
        val ENGINES = listOf("auto", "dr", "terrain", "route", "gnss")
        private val NAN_BITS = java.lang.Double.doubleToRawLongBits(Double.NaN)
        private const val KEY_HEIGHT = "height_m"
        private const val KEY_FEMALE = "female"
        private const val KEY_PARTICLES = "particles"
        private const val KEY_ENGINE = "engine"
        private const val KEY_SIGMA = "start_sigma_m"
        private const val KEY_LAT = "start_lat_deg"
        private const val KEY_LON = "start_lon_deg"
        private const val KEY_DEM = "dem_path"
        private const val KEY_GRAPH = "graph_path"
        private const val KEY_BASEMAP = "basemap_path"
        private const val KEY_NAV = "nav_path"
    }
}
