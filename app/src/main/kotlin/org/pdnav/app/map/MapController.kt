package org.pdnav.app.map

import android.content.Context
import android.graphics.Canvas
import android.graphics.Color
import android.graphics.Paint
import android.graphics.Point
import org.osmdroid.config.Configuration
import org.osmdroid.events.MapEventsReceiver
import org.osmdroid.tileprovider.modules.OfflineTileProvider
import org.osmdroid.tileprovider.tilesource.FileBasedTileSource
import org.osmdroid.tileprovider.tilesource.XYTileSource
import org.osmdroid.tileprovider.util.SimpleRegisterReceiver
import org.osmdroid.util.GeoPoint
import org.osmdroid.views.MapView
import org.osmdroid.views.overlay.MapEventsOverlay
import org.osmdroid.views.overlay.Marker
import org.osmdroid.views.overlay.Overlay
import org.osmdroid.views.overlay.Polygon
import org.osmdroid.views.overlay.Polyline
import org.pdnav.app.nav.NavEstimate
import org.pdnav.app.nav.NavOutput
import java.io.File
import kotlin.math.cos
import kotlin.math.sin

/**
 * The map screen's osmdroid view: offline MBTiles basemap only (never a network tile source),
 * the estimate as a marker, its 95 % error ellipse as a polygon, the track as a polyline and,
 * optionally, the terrain engine's particle cloud.
 */
class MapController(context: Context, val map: MapView) {
    private val marker = Marker(map)
    private val ellipse = Polygon(map)
    private val trackLine = Polyline(map)
    private val cloud = ParticleOverlay()
    var showParticles = true

    init {
        val cfg = Configuration.getInstance()
        cfg.userAgentValue = context.packageName
        cfg.osmdroidBasePath = File(context.filesDir, "osmdroid")
        cfg.osmdroidTileCache = File(context.cacheDir, "osmdroid-tiles")
        map.setUseDataConnection(false)  // offline only
        map.setMultiTouchControls(true)
        map.controller.setZoom(17.0)
        marker.setAnchor(Marker.ANCHOR_CENTER, Marker.ANCHOR_CENTER)
        marker.title = "estimate"
        ellipse.fillPaint.color = Color.argb(60, 30, 111, 217)
        ellipse.outlinePaint.color = Color.argb(200, 30, 111, 217)
        ellipse.outlinePaint.strokeWidth = 3f
        trackLine.outlinePaint.color = Color.argb(220, 217, 80, 30)
        trackLine.outlinePaint.strokeWidth = 6f
        map.overlays.add(trackLine)
        map.overlays.add(ellipse)
        map.overlays.add(cloud)
        map.overlays.add(marker)
        marker.isEnabled = false
        ellipse.isEnabled = false
    }

    /**
     * Shows the MBTiles basemap [file] (made by dem-tools) through osmdroid's offline tile
     * provider; false when there is no such file (the map then stays blank, still offline).
     */
    fun loadBasemap(context: Context, file: File?): Boolean {
        if (file == null || !file.isFile) return false
        val provider = OfflineTileProvider(SimpleRegisterReceiver(context), arrayOf(file))
        map.setTileProvider(provider)
        val names = provider.archives.flatMap { it.tileSources }
        val source = if (names.isNotEmpty()) {
            FileBasedTileSource.getSource(names.first())
        } else {
            XYTileSource("mbtiles", 0, 19, 256, ".png", arrayOf<String>())
        }
        map.setTileSource(source)
        map.setUseDataConnection(false)
        return true
    }

    /** Calls [onLongPress] with the pressed point (declaring the start position). */
    fun setOnLongPress(onLongPress: (GeoPoint) -> Unit) {
        map.overlays.add(0, MapEventsOverlay(object : MapEventsReceiver {
            override fun singleTapConfirmedHelper(p: GeoPoint) = false
            override fun longPressHelper(p: GeoPoint): Boolean {
                onLongPress(p)
                return true
            }
        }))
    }

    /** Updates marker, ellipse, track and particles from one navigator output. */
    fun show(out: NavOutput, track: List<DoubleArray>, follow: Boolean = true) {
        val e = out.estimate
        trackLine.setPoints(track.map { GeoPoint(it[0], it[1]) })
        if (!e.valid || e.latDeg.isNaN()) {
            marker.isEnabled = false
            ellipse.isEnabled = false
            cloud.points = emptyList()
            map.invalidate()
            return
        }
        val here = GeoPoint(e.latDeg, e.lonDeg)
        marker.position = here
        marker.snippet = e.statusText()
        marker.isEnabled = true
        ellipse.points = ellipsePoints(e)
        ellipse.isEnabled = true
        cloud.points = if (showParticles) particlePoints(e, out.particlesEnM) else emptyList()
        if (follow) map.controller.setCenter(here)
        map.invalidate()
    }

    /** Marks a declared start point (before the navigator has an estimate). */
    fun showStart(p: GeoPoint) {
        marker.position = p
        marker.isEnabled = true
        map.controller.setCenter(p)
        map.invalidate()
    }

    val markerShown: Boolean get() = marker.isEnabled
    val ellipsePointCount: Int get() = if (ellipse.isEnabled) ellipse.actualPoints.size else 0
    val trackPointCount: Int get() = trackLine.actualPoints.size

    companion object {
        /** 95 % content of a 2D Gaussian: k = sqrt(-2 ln 0.05). */
        const val K95 = 2.4477

        private const val EARTH_RADIUS_M = 6_371_000.0

        /** Offsets east/north (m) from a point, as a geographic point (small-offset approximation). */
        fun offset(latDeg: Double, lonDeg: Double, eastM: Double, northM: Double): GeoPoint {
            val dLat = Math.toDegrees(northM / EARTH_RADIUS_M)
            val dLon = Math.toDegrees(eastM / (EARTH_RADIUS_M * cos(Math.toRadians(latDeg))))
            return GeoPoint(latDeg + dLat, lonDeg + dLon)
        }

        /** 36 vertices of the 95 % ellipse around the estimate. */
        fun ellipsePoints(e: NavEstimate): List<GeoPoint> {
            val el = e.ellipse()
            val th = el.orientationRad  // clockwise from north
            return (0 until 36).map { k ->
                val t = 2.0 * Math.PI * k / 36
                val a = K95 * el.semiMajorM * cos(t)
                val b = K95 * el.semiMinorM * sin(t)
                // major axis along (sin th, cos th), minor along (cos th, -sin th) in (east, north)
                offset(e.latDeg, e.lonDeg, a * sin(th) + b * cos(th), a * cos(th) - b * sin(th))
            }
        }

        /** Particles are east/north in the engine frame: place them relative to the estimate. */
        fun particlePoints(e: NavEstimate, en: DoubleArray): List<GeoPoint> =
            (0 until en.size / 2).map { i -> offset(e.latDeg, e.lonDeg, en[2 * i] - e.eastM, en[2 * i + 1] - e.northM) }
    }

    /** Draws the particle cloud as small dots. */
    private class ParticleOverlay : Overlay() {
        var points: List<GeoPoint> = emptyList()
        private val paint = Paint().apply { color = Color.argb(160, 40, 160, 60); isAntiAlias = true }
        private val px = Point()

        override fun draw(c: Canvas, osmv: MapView, shadow: Boolean) {
            if (shadow) return
            val proj = osmv.projection
            for (p in points) {
                proj.toPixels(p, px)
                c.drawCircle(px.x.toFloat(), px.y.toFloat(), 3f, paint)
            }
        }
    }
}
