package org.pdnav.app.ui

import android.content.Context
import android.graphics.Canvas
import android.graphics.Color
import android.graphics.Paint
import android.graphics.Rect
import android.graphics.RectF
import android.view.View
import org.pdnav.app.sensors.GnssSource
import kotlin.math.cos
import kotlin.math.min
import kotlin.math.sin

/**
 * GPSTest's satellite view for the latest GnssStatus. Top: the sky plot, each satellite at its
 * azimuth (clockwise from north, up) and elevation (centre = zenith, edge = horizon), coloured
 * by constellation, filled when used in the fix, a ring when not, its size by C/N0. Bottom: a
 * C/N0 bar per satellite (0..[CN0_FULL_DBHZ] dB-Hz, same colours, pale when not used) with its
 * svid under it. The geometry functions are public so the host test can check the pixels.
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
    /** A white halo under the svid labels, so a label over a grid line stays readable. */
    private val halo = Paint(text).apply { color = Color.WHITE; style = Paint.Style.STROKE; strokeWidth = 3 * density }
    private val barText = Paint(Paint.ANTI_ALIAS_FLAG).apply { color = Color.DKGRAY; textSize = 9 * density; textAlign = Paint.Align.CENTER }

    /** Height of the C/N0 bar strip (bars and their svid labels) at the bottom, px. */
    val barStripPx: Float get() = 64 * density

    /** Plot centre and radius (px) for the current size: x, y, r. */
    fun plotGeometry(): FloatArray {
        val plotH = height - barStripPx
        val r = min(width.toFloat(), plotH) / 2f - 12 * density
        return floatArrayOf(width / 2f, plotH / 2f, r)
    }

    /** Position of a satellite in the plot (x right, y down), radius r around (cx, cy). */
    fun position(azimuthDeg: Double, elevationDeg: Double, cx: Float, cy: Float, r: Float): FloatArray {
        val rho = r * (90.0 - elevationDeg.coerceIn(0.0, 90.0)) / 90.0
        val az = Math.toRadians(azimuthDeg)
        return floatArrayOf((cx + rho * sin(az)).toFloat(), (cy - rho * cos(az)).toFloat())
    }

    /** Radius (px) of a satellite's dot: 3 dp at <= 10 dB-Hz to 8 dp at >= 50 dB-Hz. */
    fun dotRadius(cn0DbHz: Double): Float = ((3 + (cn0DbHz.coerceIn(10.0, 50.0) - 10) / 8) * density).toFloat()

    /** The satellites in bar order: by constellation, then svid. */
    fun barOrder(): List<GnssSource.Satellite> = satellites.sortedWith(compareBy({ it.constellation }, { it.svid }))

    /** Bar of the k-th of n satellites (bar order) at [cn0DbHz]: filled rectangle, px. */
    fun barRect(k: Int, n: Int, cn0DbHz: Double): RectF {
        val slot = barSlot(n)
        val left = (width - slot * n) / 2f + k * slot
        val bottom = height - 14 * density
        val full = barStripPx - 22 * density
        val h = (full * (cn0DbHz.coerceIn(0.0, CN0_FULL_DBHZ) / CN0_FULL_DBHZ)).toFloat()
        return RectF(left + slot * 0.15f, bottom - h, left + slot * 0.85f, bottom)
    }

    /** Where the k-th of n svid labels is drawn (text bounds, px). */
    fun labelBounds(k: Int, n: Int, label: String): Rect {
        val bar = barRect(k, n, 0.0)
        val b = Rect()
        barText.getTextBounds(label, 0, label.length, b)
        val x = bar.centerX()
        val base = height - 3 * density
        return Rect((x - b.width() / 2f).toInt(), (base + b.top).toInt(), (x + b.width() / 2f + 1).toInt(), (base + b.bottom + 1).toInt())
    }

    /** Width of one bar slot: at most 24 dp, so all satellites fit the width. */
    private fun barSlot(n: Int): Float = if (n == 0) 0f else min(24 * density, (width - 8 * density) / n)

    override fun onDraw(c: Canvas) {
        super.onDraw(c)
        val (cx, cy, r) = plotGeometry().let { Triple(it[0], it[1], it[2]) }
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
            val size = dotRadius(s.cn0DbHz)
            c.drawCircle(p[0], p[1], size, sat)
            c.drawText(s.svid.toString(), p[0] + size, p[1] - size, halo)
            c.drawText(s.svid.toString(), p[0] + size, p[1] - size, text)
        }
        // C/N0 bars; labels only where a slot is wide enough for them
        val bars = barOrder()
        val slot = barSlot(bars.size)
        sat.style = Paint.Style.FILL
        bars.forEachIndexed { k, s ->
            if (!s.cn0DbHz.isFinite()) return@forEachIndexed
            val col = constellationColor(s.constellation)
            sat.color = if (s.usedInFix) col else Color.argb(110, Color.red(col), Color.green(col), Color.blue(col))
            c.drawRect(barRect(k, bars.size, s.cn0DbHz), sat)
            val label = s.svid.toString()
            if (barText.measureText(label) <= slot) {
                c.drawText(label, barRect(k, bars.size, 0.0).centerX(), height - 3 * density, barText)
            }
        }
    }

    companion object {
        /** C/N0 of a full bar: strong open-sky signals reach ~45-50 dB-Hz on phones. */
        const val CN0_FULL_DBHZ = 50.0

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

        /** The constellations the plot colours, in GnssStatus order (the legend). */
        val LEGEND_CONSTELLATIONS = listOf(1, 3, 4, 5, 6, 7, 2)

        /** Legend under the plot: "● GPS  ● GLONASS ...", each dot in its constellation's colour. */
        fun legend(): CharSequence {
            val b = android.text.SpannableStringBuilder()
            for (c in LEGEND_CONSTELLATIONS) {
                if (b.isNotEmpty()) b.append("  ")
                val at = b.length
                b.append("●")
                b.setSpan(android.text.style.ForegroundColorSpan(constellationColor(c)), at, at + 1, android.text.Spanned.SPAN_EXCLUSIVE_EXCLUSIVE)
                b.append("\u00A0").append(constellationName(c))  // the dot stays with its name
            }
            b.append("  (filled: used\u00A0in\u00A0the\u00A0fix)")
            return b
        }

        fun constellationName(c: Int): String = when (c) {
            1 -> "GPS"; 2 -> "SBAS"; 3 -> "GLONASS"; 4 -> "QZSS"; 5 -> "BeiDou"; 6 -> "Galileo"; 7 -> "IRNSS"
            else -> "?"
        }
    }
}
