package org.pdnav.app.ui

import android.app.Activity
import android.app.AlertDialog
import android.content.Context
import android.content.Intent
import android.graphics.Color
import android.net.Uri
import android.os.Bundle
import android.os.Handler
import android.os.Looper
import android.provider.OpenableColumns
import android.view.Gravity
import android.widget.LinearLayout
import android.widget.ScrollView
import android.widget.TextView
import org.pdnav.app.R
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import java.io.IOException
import java.util.Locale

/**
 * Installed regions (one `.pdnav-region` file each: DEM, walkway graph, basemap), with their
 * area, size and date; Import (system file picker) and "open with" a region file from
 * elsewhere (VIEW intent); Delete. The import checks the manifest, sizes and checksums on a
 * background thread and installs only a whole, verified region.
 */
class RegionsActivity : Activity() {
    private lateinit var store: RegionStore
    private lateinit var settings: AppSettings
    private lateinit var rows: LinearLayout
    private lateinit var statusText: TextView
    private val main = Handler(Looper.getMainLooper())

    /** The import running, if any (tests join it). */
    @Volatile var importThread: Thread? = null
        private set

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        store = RegionStore(filesDir)
        settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        statusText = TextView(this).apply { id = R.id.regions_status }
        rows = LinearLayout(this).apply { id = R.id.regions_list; orientation = LinearLayout.VERTICAL }
        val form = LinearLayout(this).apply {
            orientation = LinearLayout.VERTICAL
            val p = Views.dp(context, 16)
            setPadding(p, p, p, p)
            addView(Views.button(context, R.id.regions_import, getString(R.string.regions_import)) { pick() })
            addView(statusText, LinearLayout.LayoutParams(-1, -2))
            addView(rows, LinearLayout.LayoutParams(-1, -2))
        }
        val scroll = ScrollView(this).apply { addView(form) }
        Views.applySystemBarInsets(scroll, scroll, scroll)  // the form keeps its own padding
        setContentView(scroll)
        refresh()
        // "open with": a region file handed over by another app
        if (savedInstanceState == null && intent?.action == Intent.ACTION_VIEW) intent.data?.let { startImport(it) }
    }

    private fun pick() {
        val i = Intent(Intent.ACTION_OPEN_DOCUMENT).addCategory(Intent.CATEGORY_OPENABLE).setType("*/*")
        @Suppress("DEPRECATION") startActivityForResult(i, REQUEST_PICK)
    }

    @Deprecated("framework API (no AndroidX activity-result here)")
    override fun onActivityResult(requestCode: Int, resultCode: Int, data: Intent?) {
        @Suppress("DEPRECATION") super.onActivityResult(requestCode, resultCode, data)
        val uri = data?.data
        if (requestCode == REQUEST_PICK && resultCode == RESULT_OK && uri != null) startImport(uri)
    }

    /** Verifies and installs the region file at [uri] on a background thread. */
    fun startImport(uri: Uri) {
        if (importThread?.isAlive == true) return
        val label = displayName(uri) ?: uri.lastPathSegment ?: "region file"
        statusText.text = getString(R.string.regions_importing, label)
        importThread = Thread({
            val result = try {
                val input = contentResolver.openInputStream(uri) ?: throw IOException("$label: cannot open it")
                Result.success(input.use { store.install(it, label) { n -> main.post { statusText.text = getString(R.string.regions_progress, label, n / 1e6) } } })
            } catch (e: IOException) {
                Result.failure(e)
            } catch (e: SecurityException) {
                Result.failure(e)
            }
            main.post { importDone(result) }
        }, "pdnav-region-import").apply { start() }
    }

    private fun importDone(r: Result<RegionInfo>) {
        val info = r.getOrElse { e ->
            statusText.setTextColor(Color.rgb(176, 0, 32))
            statusText.text = getString(R.string.regions_refused, e.message ?: e.toString())
            refresh()
            return
        }
        settings.lastRegion = info.name
        statusText.setTextColor(Color.DKGRAY)
        statusText.text = getString(R.string.regions_installed, info.name, mb(info.bytes))
        refresh()
    }

    private fun displayName(uri: Uri): String? = try {
        contentResolver.query(uri, arrayOf(OpenableColumns.DISPLAY_NAME), null, null, null)?.use { c ->
            if (c.moveToFirst() && !c.isNull(0)) c.getString(0) else null
        }
    } catch (e: RuntimeException) {
        null
    }

    private fun refresh() {
        rows.removeAllViews()
        val regions = store.list()
        if (regions.isEmpty()) {
            rows.addView(TextView(this).apply { id = R.id.regions_empty; text = getString(R.string.regions_empty) }, LinearLayout.LayoutParams(-1, -2))
            return
        }
        for (r in regions) {
            val text = TextView(this).apply {
                textSize = 15f
                setTextColor(Color.BLACK)
                text = describe(r)
            }
            val row = LinearLayout(this).apply {
                orientation = LinearLayout.HORIZONTAL
                gravity = Gravity.CENTER_VERTICAL
                setPadding(0, Views.dp(context, 8), 0, Views.dp(context, 8))
                addView(text, LinearLayout.LayoutParams(0, -2, 1f))
                addView(Views.button(context, android.view.View.NO_ID, getString(R.string.action_delete)) { confirmDelete(r) },
                    LinearLayout.LayoutParams(-2, -2))
            }
            rows.addView(row, LinearLayout.LayoutParams(-1, -2))
        }
    }

    private fun confirmDelete(r: RegionInfo) {
        AlertDialog.Builder(this).setMessage(getString(R.string.sessions_delete_confirm, r.name))
            .setPositiveButton(R.string.action_delete) { _, _ -> delete(r.name) }
            .setNegativeButton(android.R.string.cancel, null).show()
    }

    fun delete(name: String) {
        store.delete(name)
        if (settings.lastRegion == name) settings.lastRegion = ""
        refresh()
    }

    companion object {
        private const val REQUEST_PICK = 21

        fun mb(bytes: Long): String = String.format(Locale.US, "%.1f MB", bytes / 1e6)

        /** e.g. "Andorra\n42.50-42.55° N, 1.52-1.60° E · 12.3 MB · 2026-12-03". */
        fun describe(r: RegionInfo): String {
            val b = r.bounds
            fun lat(v: Double) = String.format(Locale.US, "%.3f° %s", Math.abs(v), if (v >= 0) "N" else "S")
            fun lon(v: Double) = String.format(Locale.US, "%.3f° %s", Math.abs(v), if (v >= 0) "E" else "W")
            return r.name + "\n" + "${lat(b.southDeg)} to ${lat(b.northDeg)}, ${lon(b.westDeg)} to ${lon(b.eastDeg)}" +
                "\n" + mb(r.bytes) + (if (r.createdUtc.isNotEmpty()) " · made " + r.createdUtc.take(10) else "")
        }
    }
}
