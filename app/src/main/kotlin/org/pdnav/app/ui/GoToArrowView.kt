package org.pdnav.app.ui

import android.content.Context
import android.graphics.Canvas
import android.graphics.Color
import android.graphics.Paint
import android.graphics.Path
import android.view.View
import kotlin.math.min

/**
 * Go-to's arrow: a compass dial (north up, like the map) with an arrow towards the place,
 * or, when the position is too uncertain for a direction, a grey dial with a question mark
 * and no arrow. The bearing is the core's (geodesic inverse).
 */
class GoToArrowView(context: Context) : View(context) {
    private val density = context.resources.displayMetrics.density
    var bearingDeg: Double = Double.NaN
        set(v) { field = v; invalidate() }
    var uncertain: Boolean = false
        set(v) { field = v; invalidate() }
    private val dial = Paint(Paint.ANTI_ALIAS_FLAG).apply { style = Paint.Style.STROKE; strokeWidth = 2 * density; color = Color.GRAY }
    private val arrow = Paint(Paint.ANTI_ALIAS_FLAG).apply { color = ARROW_COLOR }
    private val text = Paint(Paint.ANTI_ALIAS_FLAG).apply { color = Color.DKGRAY; textAlign = Paint.Align.CENTER }

    /** True when an arrow is drawn (a direction the walker may trust). */
    val arrowShown: Boolean get() = !uncertain && bearingDeg.isFinite()

    override fun onDraw(c: Canvas) {
        super.onDraw(c)
        val cx = width / 2f
        val cy = height / 2f
        val r = min(width, height) / 2f - 3 * density
        c.drawCircle(cx, cy, r, dial)
        text.textSize = 10 * density
        c.drawText("N", cx, cy - r + 11 * density, text)
        if (!arrowShown) {
            text.textSize = r
            c.drawText("?", cx, cy + r / 3, text)
            return
        }
        c.save()
        c.rotate(bearingDeg.toFloat(), cx, cy)
        val p = Path().apply {
            moveTo(cx, cy - r * 0.8f)
            lineTo(cx + r * 0.4f, cy + r * 0.55f)
            lineTo(cx, cy + r * 0.3f)
            lineTo(cx - r * 0.4f, cy + r * 0.55f)
            close()
        }
        c.drawPath(p, arrow)
        c.restore()
    }

    companion object {
        val ARROW_COLOR = Color.rgb(0, 150, 200)
    }
}
