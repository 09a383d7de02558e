package org.pdnav.app.ui

import android.content.Context
import android.graphics.Canvas
import android.graphics.Color
import android.graphics.Paint
import android.view.View
import org.pdnav.app.sensors.GnssSource
import kotlin.math.cos
import kotlin.math.min
import kotlin.math.sin

/**
 * GPSTest's sky plot: each satellite of the latest GnssStatus at its azimuth (clockwise from
 * north, up) and elevation (centre = zenith, edge = horizon), coloured by constellation,
 * filled when used in the fix, its size by C/N0.
 */
class SkyPlotView(context: Context) : View(context) {
    var satellites: List<GnssSource.Satellite> = emptyList()
        set(v) {
            field = v
            invalidate()
        }
    private val density = context.resources.displayMetrics.density
    private val grid = Paint(Paint.ANTI_ALIAS_FLAG).apply { color = Color.GRAY; style = Paint.Style.STROKE; strokeWidth = density }
    private val sat = Paint(Paint.ANTI_ALIAS_FLAG)
    private val text = Paint(Paint.ANTI_ALIAS_FLAG).apply { color = Color.DKGRAY; textSize = 10 * density }

    /** Position of a satellite in the plot (x right, y down), radius r around (cx, cy). */
    fun position(azimuthDeg: Double, elevationDeg: Double, cx: Float, cy: Float, r: Float): FloatArray {
        val rho = r * (90.0 - elevationDeg.coerceIn(0.0, 90.0)) / 90.0
        val az = Math.toRadians(azimuthDeg)
        return floatArrayOf((cx + rho * sin(az)).toFloat(), (cy - rho * cos(az)).toFloat())
    }

    override fun onDraw(c: Canvas) {
        super.onDraw(c)
        val cx = width / 2f
        val cy = height / 2f
        val r = min(width, height) / 2f - 12 * density
        if (r <= 0) return
        for (el in listOf(0, 30, 60)) c.drawCircle(cx, cy, r * (90 - el) / 90f, grid)
        c.drawLine(cx - r, cy, cx + r, cy, grid)
        c.drawLine(cx, cy - r, cx, cy + r, grid)
        c.drawText("N", cx + 2 * density, cy - r + 10 * density, text)
        for (s in satellites) {
            if (!s.elevationDeg.isFinite() || !s.azimuthDeg.isFinite() || s.elevationDeg < 0) continue
            val p = position(s.azimuthDeg, s.elevationDeg, cx, cy, r)
            sat.color = constellationColor(s.constellation)
            sat.style = if (s.usedInFix) Paint.Style.FILL else Paint.Style.STROKE
            sat.strokeWidth = 2 * density
            val size = (3 + (s.cn0DbHz.coerceIn(10.0, 50.0) - 10) / 8).toFloat() * density
            c.drawCircle(p[0], p[1], size, sat)
            c.drawText(s.svid.toString(), p[0] + size, p[1] - size, text)
        }
    }

    companion object {
        /** GnssStatus.CONSTELLATION_* -> colour (GPS, SBAS, GLONASS, QZSS, BeiDou, Galileo, IRNSS). */
        fun constellationColor(c: Int): Int = when (c) {
            1 -> Color.rgb(30, 111, 217)
            2 -> Color.rgb(120, 120, 120)
            3 -> Color.rgb(217, 50, 50)
            4 -> Color.rgb(200, 120, 0)
            5 -> Color.rgb(230, 180, 0)
            6 -> Color.rgb(40, 160, 60)
            7 -> Color.rgb(140, 60, 200)
            else -> Color.BLACK
        }

        fun constellationName(c: Int): String = when (c) {
            1 -> "GPS"; 2 -> "SBAS"; 3 -> "GLONASS"; 4 -> "QZSS"; 5 -> "BeiDou"; 6 -> "Galileo"; 7 -> "IRNSS"
            else -> "?"
        }
    }
}
