package org.pdnav.app.walk

import org.pdnav.app.nav.NativeNavigator
import org.pdnav.app.nav.NativeRouter
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.nav.SampleSink
import org.pdnav.app.nav.SessionFeeder
import org.pdnav.app.region.PlaceStore
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import java.io.File

/**
 * The session's navigator, opened on the region the walk is in. While regions are
 * installed, the stream is held (in order) until it shows where the walk is: a declared
 * start (`StartLatitudeDegrees`/`StartLongitudeDegrees` Meta rows) or the first GNSS fix
 * with a position; the region containing that point gives the DEM and walkway graph (its
 * basemap is for the screen). Outside every region, or with none installed, the settings'
 * single files are used (tester imports). The held rows are then fed in order, so live and
 * replay see the same stream and a replay picks the same region. Without any region the
 * navigator opens at once (nothing is held).
 *
 * After every write the per-step estimates go to [tracker] (distance walked, start place,
 * leaving the region, Go-to). Runs on the feeding thread.
 */
class RegionalNavigator(
    private val baseConfig: NavigatorConfig,
    private val seed: Long,
    private val regions: RegionStore?,
    private val filesDir: File?,
    /** Save the session start as a place (live sessions; not replays). */
    private val saveStart: Boolean,
    private val onOpened: (RegionalNavigator) -> Unit = {},
) : SampleSink, AutoCloseable {
    var navigator: NativeNavigator? = null
        private set
    var feeder: SessionFeeder? = null
        private set
    var tracker: WalkTracker? = null
        private set
    var region: RegionInfo? = null
        private set
    var config: NavigatorConfig = baseConfig
        private set

    /** A Go-to target set before the navigator opened. */
    @Volatile var pendingTarget: org.pdnav.app.region.Place? = null

    private val held = SampleBatch(1024)
    private var lat = Double.NaN
    private var lon = Double.NaN
    private var closed = false

    /** Rows held while waiting for a position (tests). */
    val heldRows: Int get() = held.size

    init {
        if (regions == null || regions.list().isEmpty()) open(Double.NaN, Double.NaN)
    }

    override fun write(batch: SampleBatch) {
        val f = feeder
        if (f != null) {
            f.write(batch)
            track()
            return
        }
        var at = Double.NaN to Double.NaN
        for (i in 0 until batch.size) {
            held.addCopy(batch, i)
            if (at.first.isFinite()) continue
            when (batch.kind(i)) {
                SampleKind.META -> when (batch.string(i, 0)) {
                    SessionFeeder.KEY_LAT -> lat = batch.string(i, 1).toDoubleOrNull() ?: Double.NaN
                    SessionFeeder.KEY_LON -> {
                        lon = batch.string(i, 1).toDoubleOrNull() ?: Double.NaN
                        if (lat.isFinite() && lon.isFinite()) at = lat to lon
                    }
                }
                SampleKind.FIX -> {
                    val a = batch.double(i, 0)
                    val b = batch.double(i, 1)
                    if (a.isFinite() && b.isFinite() && a in -90.0..90.0 && b in -180.0..180.0 && !(a == 0.0 && b == 0.0)) at = a to b
                }
            }
        }
        if (at.first.isFinite() || held.size >= MAX_HELD_ROWS) open(at.first, at.second)
    }

    /** Opens the navigator now (on the region containing the point, if any) and feeds what was held. */
    private fun open(latDeg: Double, lonDeg: Double) {
        if (closed || navigator != null) return
        val r = regions?.containing(latDeg, lonDeg)
        region = r
        config = if (r != null) baseConfig.copy(demPath = r.demPath, graphPath = r.graphPath) else baseConfig
        val nav = NativeNavigator(config, seed)
        navigator = nav
        val f = SessionFeeder(nav)
        feeder = f
        val router = config.graphPath.takeIf { it.isNotEmpty() && File(it).isFile }?.let {
            try {
                NativeRouter(it)
            } catch (e: Exception) {
                null  // Go-to then shows the straight line only; the navigator reports the graph itself
            }
        }
        val places = if (saveStart && filesDir != null) PlaceStore(filesDir, r?.name) else null
        tracker = WalkTracker(r, router, places).also { t -> pendingTarget?.let { t.target = it } }
        onOpened(this)
        if (held.size > 0) {
            val chunk = SampleBatch(CHUNK)
            var i = 0
            while (i < held.size) {
                chunk.clear()
                val end = minOf(held.size, i + CHUNK)
                for (k in i until end) chunk.addCopy(held, k)
                f.write(chunk)
                i = end
            }
            held.clear()
            track()
        }
    }

    private fun track() {
        val nav = navigator ?: return
        tracker?.onSteps(nav.takeSteps())
    }

    /** Sets (or clears) the Go-to target. */
    fun setTarget(p: org.pdnav.app.region.Place?) {
        pendingTarget = p
        tracker?.target = p
    }

    /** End of input: opens the navigator on what was held (no position seen), then finish(). */
    fun finish() {
        if (navigator == null) open(lat, lon)
        navigator?.finish()
        track()
    }

    override fun close() {
        closed = true
        tracker?.close()
        navigator?.close()
    }

    companion object {
        /** At most this many rows wait for a position (about a minute of a phone's sensors). */
        const val MAX_HELD_ROWS = 30_000
        private const val CHUNK = 512
    }
}
