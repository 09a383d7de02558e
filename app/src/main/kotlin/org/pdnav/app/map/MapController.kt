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
 * the estimate as a marker anchored at the position with an arrow turned to the latest
 * step's heading (the one the heading text says), its 95 % error
 * ellipse as a polygon, the track as a polyline, the phone's own GNSS fix with its accuracy
 * circle, every engine's estimate in its own colour and, optionally, the terrain engine's
 * particle cloud. The map opens on the basemap's area (or the last fix) and follows the
 * estimate only while [follow] is on (a pan by the user switches it off).
 */
class MapController(context: Context, val map: MapView) {
    private val marker = Marker(map)
    private val ellipse = Polygon(map)
    private val trackLine = Polyline(map)
    private val cloud = ParticleOverlay()
    private val engineDots = EngineOverlay()
    private val fixCircle = Polygon(map)
    private val fixMarker = Marker(map)
    /** Go-to: the shortest walkway route (core router) and the place it leads to. */
    val routeLine = Polyline(map)
    private val targetMarker = Marker(map)
    private val density = context.resources.displayMetrics.density
    var showParticles = true

    /** The tester's layers (each engine's ring, the particle cloud): shown with the details. */
    var testerLayers: Boolean
        get() = cloud.isEnabled
        set(v) {
            cloud.isEnabled = v
            engineDots.isEnabled = v
            map.invalidate()
        }

    /** Follow the estimate (re-centre on every output) or leave the map where the user put it. */
    var follow = true

    /** Called when a user gesture switched [follow] off (the screen updates its toggle). */
    var onFollowChanged: (Boolean) -> Unit = {}

    init {
        val cfg = Configuration.getInstance()
        cfg.userAgentValue = context.packageName
        cfg.osmdroidBasePath = File(context.filesDir, "osmdroid")
        cfg.osmdroidTileCache = File(context.cacheDir, "osmdroid-tiles")
        map.setUseDataConnection(false)  // offline only
        map.setMultiTouchControls(true)
        map.controller.setZoom(DEFAULT_ZOOM)
        marker.setAnchor(Marker.ANCHOR_CENTER, Marker.ANCHOR_CENTER)  // the icon's centre is the position
        marker.icon = android.graphics.drawable.BitmapDrawable(context.resources, arrowBitmap(Color.rgb(30, 111, 217), density))
        marker.isFlat = true  // the arrow keeps its bearing when the map rotates
        marker.title = "estimate"
        fixMarker.setAnchor(Marker.ANCHOR_CENTER, Marker.ANCHOR_CENTER)
        fixMarker.icon = android.graphics.drawable.BitmapDrawable(context.resources, dotBitmap(FIX_COLOR, density))
        fixMarker.title = "phone GNSS fix"
        fixCircle.fillPaint.color = Color.argb(40, 120, 60, 200)
        fixCircle.outlinePaint.color = Color.argb(160, 120, 60, 200)
        fixCircle.outlinePaint.strokeWidth = 2f
        ellipse.fillPaint.color = Color.argb(60, 30, 111, 217)
        ellipse.outlinePaint.color = Color.argb(200, 30, 111, 217)
        ellipse.outlinePaint.strokeWidth = 3f
        trackLine.outlinePaint.color = Color.argb(220, 217, 80, 30)
        trackLine.outlinePaint.strokeWidth = 6f
        routeLine.outlinePaint.color = ROUTE_COLOR
        routeLine.outlinePaint.strokeWidth = 5f * density
        routeLine.infoWindow = null
        targetMarker.setAnchor(Marker.ANCHOR_CENTER, Marker.ANCHOR_CENTER)
        targetMarker.icon = android.graphics.drawable.BitmapDrawable(context.resources, dotBitmap(ROUTE_COLOR, density * 1.4f))
        targetMarker.title = "Go to"
        map.overlays.add(routeLine)
        map.overlays.add(targetMarker)
        routeLine.isEnabled = false
        targetMarker.isEnabled = false
        map.overlays.add(trackLine)
        map.overlays.add(fixCircle)
        map.overlays.add(ellipse)
        map.overlays.add(cloud)
        map.overlays.add(engineDots)
        map.overlays.add(fixMarker)
        map.overlays.add(marker)
        marker.isEnabled = false
        ellipse.isEnabled = false
        cloud.isEnabled = false
        engineDots.isEnabled = false
        fixMarker.isEnabled = false
        fixCircle.isEnabled = false
        map.setOnTouchListener { _, ev ->
            // a drag by the user frees the map (Follow switches off)
            if (ev.actionMasked == android.view.MotionEvent.ACTION_MOVE && follow) {
                follow = false
                onFollowChanged(false)
            }
            false
        }
    }

    private val graphLines = mutableListOf<Polyline>()

    /**
     * The walkway graph (what the route engine matches against) drawn over the basemap's
     * hillshade, below the track and the estimate.
     */
    fun showGraph(lines: List<List<DoubleArray>>) {
        map.overlays.removeAll(graphLines.toSet())
        graphLines.clear()
        val at = map.overlays.indexOf(trackLine).coerceAtLeast(0)
        for (l in lines) {
            val p = Polyline(map)
            p.outlinePaint.color = Color.argb(200, 90, 90, 90)
            p.outlinePaint.strokeWidth = 2.5f * density
            p.setPoints(l.map { GeoPoint(it[0], it[1]) })
            p.infoWindow = null
            graphLines += p
        }
        map.overlays.addAll(at, graphLines)
        map.invalidate()
    }

    val graphEdgeCount: Int get() = graphLines.size

    /** Go-to: draws [route] (lat, lon points) and the place; null hides them. */
    fun showGoTo(targetLatDeg: Double, targetLonDeg: Double, route: List<DoubleArray>?) {
        if (!targetLatDeg.isFinite()) {
            routeLine.isEnabled = false
            targetMarker.isEnabled = false
            map.invalidate()
            return
        }
        targetMarker.position = GeoPoint(targetLatDeg, targetLonDeg)
        targetMarker.isEnabled = true
        if (route != null && route.size >= 2) {
            routeLine.setPoints(route.map { GeoPoint(it[0], it[1]) })
            routeLine.isEnabled = true
        } else {
            routeLine.isEnabled = false
        }
        map.invalidate()
    }

    val routePointCount: Int get() = if (routeLine.isEnabled) routeLine.actualPoints.size else 0
    val targetShown: Boolean get() = targetMarker.isEnabled

    /** Area the basemap covers, once loaded. */
    var basemapBounds: GeoBounds? = null
        private set

    /** Centres the map on [b] (the basemap's or DEM's area). */
    fun centerOn(b: GeoBounds) {
        map.controller.setCenter(GeoPoint(b.centerLatDeg, b.centerLonDeg))
    }

    fun centerOn(latDeg: Double, lonDeg: Double) {
        map.controller.setCenter(GeoPoint(latDeg, lonDeg))
    }

    val centerLatDeg: Double get() = map.mapCenter.latitude
    val centerLonDeg: Double get() = map.mapCenter.longitude

    /** The phone's own GNSS fix and its accuracy circle (1 sigma as the phone reports it). */
    fun showFix(latDeg: Double, lonDeg: Double, accuracyM: Double) {
        if (!latDeg.isFinite() || !lonDeg.isFinite()) {
            fixMarker.isEnabled = false
            fixCircle.isEnabled = false
            return
        }
        fixMarker.position = GeoPoint(latDeg, lonDeg)
        fixMarker.isEnabled = true
        if (accuracyM.isFinite() && accuracyM > 0) {
            fixCircle.points = (0 until 36).map { k ->
                val t = 2.0 * Math.PI * k / 36
                offset(latDeg, lonDeg, accuracyM * sin(t), accuracyM * cos(t))
            }
            fixCircle.isEnabled = true
        } else {
            fixCircle.isEnabled = false
        }
        map.invalidate()
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
        basemapBounds = MbtilesBounds.read(file)?.also { centerOn(it) }
        // offline tiles only: never zoom past the deepest zoom the file has (blank grid there)
        MbtilesBounds.maxZoom(file)?.let { z ->
            map.maxZoomLevel = z.toDouble()
            map.controller.setZoom(minOf(DEFAULT_ZOOM, z.toDouble()))
        }
        return true
    }

    /** A single tap on the map (picking a checkpoint); null = taps do nothing. */
    var onTap: ((GeoPoint) -> Unit)? = null

    /** Calls [onLongPress] with the pressed point (declaring the start position). */
    fun setOnLongPress(onLongPress: (GeoPoint) -> Unit) {
        map.overlays.add(0, MapEventsOverlay(object : MapEventsReceiver {
            override fun singleTapConfirmedHelper(p: GeoPoint): Boolean {
                val f = onTap ?: return false
                f(p)
                return true
            }
            override fun longPressHelper(p: GeoPoint): Boolean {
                onLongPress(p)
                return true
            }
        }))
    }

    /** Updates marker, ellipse, track and particles from one navigator output. */
    fun show(out: NavOutput, track: List<DoubleArray>) {
        val e = out.estimate
        trackLine.setPoints(track.map { GeoPoint(it[0], it[1]) })
        engineDots.engines = out.engines.filter { it.valid && it.latDeg.isFinite() }
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
        (if (stepHeadingDeg.isFinite()) stepHeadingDeg else headingDeg(track))?.let { setMarkerHeading(it) }
        ellipse.points = ellipsePoints(e)
        ellipse.isEnabled = true
        cloud.points = if (showParticles) particlePoints(e, out.particlesEnM) else emptyList()
        if (follow) map.controller.setCenter(here)
        map.invalidate()
    }

    /**
     * The walker's heading, degrees clockwise from true north: the latest step's (the core's
     * calibrated walking direction, the one the heading text says). NaN before the first step;
     * the arrow then follows the track's direction, if any.
     */
    private var stepHeadingDeg = Double.NaN

    /** Turns the arrow to the latest step's heading [deg] (NaN: none yet, e.g. a new session). */
    fun showHeading(deg: Double) {
        stepHeadingDeg = deg
        if (deg.isFinite()) {
            setMarkerHeading(deg)
            map.invalidate()
        }
    }

    /**
     * osmdroid draws a flat marker rotated by -rotation degrees (canvas degrees, clockwise on
     * screen) in the map's frame (the canvas is already turned by the map's orientation), so a
     * rotation of -heading points the arrow at that bearing from the map's north.
     */
    private fun setMarkerHeading(deg: Double) {
        marker.rotation = -deg.toFloat()
    }

    /** The bearing the arrow points at on the map, degrees clockwise from north, [0, 360). */
    val markerHeadingDeg: Double get() = ((-marker.rotation.toDouble()) % 360.0 + 360.0) % 360.0

    /** The estimate's arrow (tests compare its picture with its heading). */
    val estimateMarker: Marker get() = marker

    /** Engines drawn (valid positions of NavOutput.engines). */
    val engineCount: Int get() = engineDots.engines.size
    val fixShown: Boolean get() = fixMarker.isEnabled

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
        private val FIX_COLOR = Color.rgb(120, 60, 200)
        /** Go-to route and place: a saturated blue-green no basemap layer uses. */
        val ROUTE_COLOR = Color.rgb(0, 150, 200)

        /** Colour of each engine (EngineKind order): none, DR, terrain, route, GNSS. */
        val ENGINE_COLORS = intArrayOf(Color.GRAY, Color.rgb(230, 140, 0), Color.rgb(40, 160, 60),
            Color.rgb(200, 30, 120), Color.rgb(120, 60, 200))

        /**
         * Direction of travel, degrees clockwise from north, from the last track points at
         * least 2 m apart; null while standing. Only until the first step's heading arrives
         * ([showHeading]): the fused track bends with the filter's corrections, the step's
         * heading is the walker's.
         */
        fun headingDeg(track: List<DoubleArray>): Double? {
            if (track.size < 2) return null
            val last = track.last()
            for (i in track.size - 2 downTo maxOf(0, track.size - 50)) {
                val p = track[i]
                val north = Math.toRadians(last[0] - p[0]) * EARTH_RADIUS_M
                val east = Math.toRadians(last[1] - p[1]) * EARTH_RADIUS_M * cos(Math.toRadians(last[0]))
                if (north * north + east * east >= 4.0) return (Math.toDegrees(Math.atan2(east, north)) + 360.0) % 360.0
            }
            return null
        }

        /** An arrow pointing up (north before rotation), centred on the bitmap. */
        fun arrowBitmap(color: Int, density: Float): android.graphics.Bitmap {
            val size = (28 * density).toInt().coerceAtLeast(8)
            val b = android.graphics.Bitmap.createBitmap(size, size, android.graphics.Bitmap.Config.ARGB_8888)
            val c = Canvas(b)
            val fill = Paint(Paint.ANTI_ALIAS_FLAG).apply { this.color = color }
            val edge = Paint(Paint.ANTI_ALIAS_FLAG).apply { this.color = Color.WHITE; style = Paint.Style.STROKE; strokeWidth = 2 * density }
            val path = android.graphics.Path().apply {
                moveTo(size / 2f, size * 0.05f)
                lineTo(size * 0.85f, size * 0.9f)
                lineTo(size / 2f, size * 0.7f)
                lineTo(size * 0.15f, size * 0.9f)
                close()
            }
            c.drawPath(path, fill)
            c.drawPath(path, edge)
            return b
        }

        fun dotBitmap(color: Int, density: Float): android.graphics.Bitmap {
            val size = (14 * density).toInt().coerceAtLeast(4)
            val b = android.graphics.Bitmap.createBitmap(size, size, android.graphics.Bitmap.Config.ARGB_8888)
            val c = Canvas(b)
            c.drawCircle(size / 2f, size / 2f, size / 2f, Paint(Paint.ANTI_ALIAS_FLAG).apply { this.color = Color.WHITE })
            c.drawCircle(size / 2f, size / 2f, size / 2f - 2 * density, Paint(Paint.ANTI_ALIAS_FLAG).apply { this.color = color })
            return b
        }

        const val DEFAULT_ZOOM = 17.0

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

    /** Each engine's estimate as a ring in its colour, labelled with the engine's name. */
    private inner class EngineOverlay : Overlay() {
        var engines: List<NavEstimate> = emptyList()
        private val ring = Paint(Paint.ANTI_ALIAS_FLAG).apply { style = Paint.Style.STROKE; strokeWidth = 3 * density }
        private val label = Paint(Paint.ANTI_ALIAS_FLAG).apply { textSize = 11 * density }
        private val px = Point()

        override fun draw(c: Canvas, osmv: MapView, shadow: Boolean) {
            if (shadow) return
            val proj = osmv.projection
            for (e in engines) {
                val color = ENGINE_COLORS.getOrElse(e.engineCode) { Color.GRAY }
                ring.color = color
                label.color = color
                proj.toPixels(GeoPoint(e.latDeg, e.lonDeg), px)
                c.drawCircle(px.x.toFloat(), px.y.toFloat(), 7 * density, ring)
                c.drawText(e.engine.label, px.x + 9 * density, px.y - 9 * density, label)
            }
        }
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
