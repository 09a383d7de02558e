package org.pdnav.app.ui

import android.app.Activity
import android.content.Intent
import android.graphics.Color
import android.os.Bundle
import android.view.Gravity
import android.widget.LinearLayout
import android.widget.ScrollView
import android.widget.TextView
import org.pdnav.app.R
import org.pdnav.app.region.Place
import org.pdnav.app.region.PlaceStore
import java.text.SimpleDateFormat
import java.util.Date
import java.util.Locale

/**
 * The places of the region the walker is in (session starts, saved places, checkpoints),
 * kept across sessions; each with Go to (back to the map, which then shows bearing, distance
 * and the walkway route) and Delete.
 */
class PlacesActivity : Activity() {
    private lateinit var store: PlaceStore
    private lateinit var rows: LinearLayout

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        val region = intent?.getStringExtra(EXTRA_REGION)?.takeIf { it.isNotEmpty() }
        store = PlaceStore(filesDir, region)
        rows = LinearLayout(this).apply {
            id = R.id.places_list
            orientation = LinearLayout.VERTICAL
            val p = Views.dp(context, 16)
            setPadding(p, p, p, p)
        }
        val scroll = ScrollView(this).apply { addView(rows) }
        Views.applySystemBarInsets(scroll, scroll, scroll)  // the list keeps its own padding
        setContentView(scroll)
        title = if (region != null) getString(R.string.places_header, region) else getString(R.string.places_header_none)
    }

    override fun onResume() {
        super.onResume()
        refresh()
    }

    /** Places, newest first. */
    fun shown(): List<Place> = store.list().sortedByDescending { it.createdMs }

    private fun refresh() {
        rows.removeAllViews()
        val places = shown()
        if (places.isEmpty()) {
            rows.addView(TextView(this).apply { id = R.id.places_empty; text = getString(R.string.places_empty) },
                LinearLayout.LayoutParams(-1, -2))
            return
        }
        val fmt = SimpleDateFormat("yyyy-MM-dd HH:mm", Locale.US)
        for (p in places) {
            val text = TextView(this).apply {
                textSize = 15f
                setTextColor(Color.BLACK)
                text = p.name + "\n" + String.format(Locale.US, "%s · %.5f, %.5f%s", kindWord(p.kind), p.latDeg, p.lonDeg,
                    if (p.createdMs > 0) " · " + fmt.format(Date(p.createdMs)) else "")
            }
            val row = LinearLayout(this).apply {
                orientation = LinearLayout.HORIZONTAL
                gravity = Gravity.CENTER_VERTICAL
                setPadding(0, Views.dp(context, 6), 0, Views.dp(context, 6))
                addView(text, LinearLayout.LayoutParams(0, -2, 1f))
                addView(Views.button(context, android.view.View.NO_ID, getString(R.string.action_goto)) { goTo(p) }, LinearLayout.LayoutParams(-2, -2))
                addView(Views.button(context, android.view.View.NO_ID, getString(R.string.action_delete)) { store.remove(p); refresh() },
                    LinearLayout.LayoutParams(-2, -2))
            }
            rows.addView(row, LinearLayout.LayoutParams(-1, -2))
        }
    }

    private fun kindWord(kind: String) = when (kind) {
        Place.START -> "walk start"
        Place.CHECKPOINT -> "checkpoint"
        else -> "saved place"
    }

    /** Back to the map with Go-to [p]. */
    fun goTo(p: Place) {
        startActivity(Intent(this, MainActivity::class.java)
            .addFlags(Intent.FLAG_ACTIVITY_CLEAR_TOP or Intent.FLAG_ACTIVITY_SINGLE_TOP)
            .putExtra(MainActivity.EXTRA_GOTO_NAME, p.name)
            .putExtra(MainActivity.EXTRA_GOTO_LAT, p.latDeg)
            .putExtra(MainActivity.EXTRA_GOTO_LON, p.lonDeg))
        finish()
    }

    companion object {
        const val EXTRA_REGION = "org.pdnav.app.extra.REGION"
    }
}
