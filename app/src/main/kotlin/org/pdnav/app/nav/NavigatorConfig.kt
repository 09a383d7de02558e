package org.pdnav.app.nav

/** pdnav::fusion::NavigatorConfig: what the settings screen sets. Defaults are the core's. */
data class NavigatorConfig(
    /** "auto", "dr", "terrain", "route" or "gnss". */
    val mode: String = "auto",
    val startLatDeg: Double = Double.NaN,
    val startLonDeg: Double = Double.NaN,
    val startSigmaM: Double = 5.0,
    val userHeightM: Double = 1.75,
    val userFemale: Boolean = false,
    val demPath: String = "",
    val graphPath: String = "",
    val navPaths: List<String> = emptyList(),
    val particles: Int = 500,
    val terrainPreset: String = "srtm",
)

/** Anything that takes time-ordered sample batches: the navigator, the recorder. */
interface SampleSink {
    fun write(batch: SampleBatch)
}
