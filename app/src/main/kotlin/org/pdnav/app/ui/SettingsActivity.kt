package org.pdnav.app.ui

import android.app.Activity
import android.content.Context
import android.content.Intent
import android.net.Uri
import android.os.Bundle
import android.os.Handler
import android.os.Looper
import android.view.View
import android.widget.ProgressBar
import android.provider.OpenableColumns
import android.text.InputType
import android.widget.ArrayAdapter
import android.widget.CheckBox
import android.widget.EditText
import android.widget.LinearLayout
import android.widget.ScrollView
import android.widget.Spinner
import android.widget.TextView
import android.widget.Toast
import org.pdnav.app.R
import java.io.File

/**
 * Start screen / settings: start uncertainty (the point itself is a long-press on the map,
 * for one session; without one the navigator starts at the first GNSS fix), user height and
 * sex (step length), particle count, engine, GNSS full tracking, and the DEM, walkway graph,
 * basemap and RINEX navigation files, imported through the system file picker
 * (ACTION_OPEN_DOCUMENT) and copied into app storage on a background thread with progress.
 */
class SettingsActivity : Activity() {
    private lateinit var settings: AppSettings
    private lateinit var heightField: EditText
    private lateinit var female: CheckBox
    private lateinit var particles: EditText
    private lateinit var engine: Spinner
    private lateinit var sigma: EditText
    private lateinit var fullTracking: CheckBox
    private lateinit var progress: ProgressBar
    private lateinit var progressText: TextView
    private val fileLabels = mutableMapOf<Int, TextView>()
    private val main = Handler(Looper.getMainLooper())

    /** The import running on its thread, if any (tests join it). */
    @Volatile var importThread: Thread? = null
        private set

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        settings = AppSettings(getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE))
        setContentView(ScrollView(this).apply { addView(buildForm()) })
    }

    private fun number(id: Int, value: String, decimal: Boolean) = EditText(this).apply {
        this.id = id
        setText(value)
        inputType = InputType.TYPE_CLASS_NUMBER or (if (decimal) InputType.TYPE_NUMBER_FLAG_DECIMAL else 0)
    }

    private fun buildForm(): LinearLayout = LinearLayout(this).apply {
        orientation = LinearLayout.VERTICAL
        val p = Views.dp(context, 16)
        setPadding(p, p, p, p)
        // the walker's map data: one region file each (the single files below are for testers)
        addView(Views.button(context, R.id.settings_regions, getString(R.string.settings_regions)) {
            startActivity(Intent(this@SettingsActivity, RegionsActivity::class.java))
        })
        heightField = number(R.id.settings_height, settings.heightM.toString(), true)
        female = CheckBox(this@SettingsActivity).apply {
            id = R.id.settings_female
            text = getString(R.string.settings_female)
            isChecked = settings.female
        }
        particles = number(R.id.settings_particles, settings.particles.toString(), false)
        sigma = number(R.id.settings_sigma, settings.startSigmaM.toString(), true)
        engine = Spinner(this@SettingsActivity).apply {
            id = R.id.settings_engine
            adapter = ArrayAdapter(this@SettingsActivity, android.R.layout.simple_spinner_dropdown_item, AppSettings.ENGINES)
            setSelection(AppSettings.ENGINES.indexOf(settings.engine).coerceAtLeast(0))
        }
        addView(Views.label(context, getString(R.string.settings_height))); addView(heightField)
        addView(female)
        addView(Views.label(context, getString(R.string.settings_particles))); addView(particles)
        addView(Views.label(context, getString(R.string.settings_engine))); addView(engine)
        addView(Views.label(context, getString(R.string.settings_sigma))); addView(sigma)
        fullTracking = CheckBox(this@SettingsActivity).apply {
            id = R.id.settings_full_tracking
            text = getString(R.string.settings_full_tracking)
            isChecked = settings.fullTracking
            isEnabled = android.os.Build.VERSION.SDK_INT >= 31
        }
        addView(fullTracking)
        // a multi-line note: as wide as the form, so its lines wrap to the box it is drawn in
        addView(TextView(context).apply { text = getString(R.string.settings_start_note) },
            LinearLayout.LayoutParams(LinearLayout.LayoutParams.MATCH_PARENT, LinearLayout.LayoutParams.WRAP_CONTENT))
        progress = ProgressBar(context, null, android.R.attr.progressBarStyleHorizontal).apply {
            id = R.id.settings_progress
            max = 1000
            visibility = View.GONE
        }
        progressText = TextView(context).apply { id = R.id.settings_progress_text }
        addView(progress)
        addView(progressText)
        addFilePicker(this, PICK_DEM, R.string.settings_pick_dem, settings.demPath)
        addFilePicker(this, PICK_GRAPH, R.string.settings_pick_graph, settings.graphPath)
        addFilePicker(this, PICK_BASEMAP, R.string.settings_pick_basemap, settings.basemapPath)
        addFilePicker(this, PICK_NAV, R.string.settings_pick_nav, settings.navPath)
        addView(Views.button(context, R.id.settings_save, getString(R.string.settings_save)) { save() })
    }

    private fun addFilePicker(parent: LinearLayout, request: Int, label: Int, current: String) {
        parent.addView(Views.button(this, android.view.View.NO_ID, getString(label)) {
            val pick = Intent(Intent.ACTION_OPEN_DOCUMENT).addCategory(Intent.CATEGORY_OPENABLE).setType("*/*")
            startActivityForResult(pick, request)
        })
        val shown = TextView(this).apply { text = current.ifEmpty { getString(R.string.settings_none) } }
        fileLabels[request] = shown
        parent.addView(shown)
    }

    /** Validates and stores the form; invalid numbers keep the old value and say so. */
    fun save() {
        val h = heightField.text.toString().toDoubleOrNull()
        val n = particles.text.toString().toIntOrNull()
        val s = sigma.text.toString().toDoubleOrNull()
        if (h == null || h !in 1.0..2.5 || n == null || n !in 10..20000 || s == null || s <= 0.0) {
            Toast.makeText(this, "height 1-2.5 m, particles 10-20000, uncertainty > 0", Toast.LENGTH_LONG).show()
            return
        }
        settings.heightM = h
        settings.particles = n
        settings.startSigmaM = s
        settings.female = female.isChecked
        settings.fullTracking = fullTracking.isChecked
        settings.engine = AppSettings.ENGINES[engine.selectedItemPosition.coerceIn(0, AppSettings.ENGINES.size - 1)]
        finish()
    }

    @Deprecated("framework API (no AndroidX activity-result here)")
    override fun onActivityResult(requestCode: Int, resultCode: Int, data: Intent?) {
        @Suppress("DEPRECATION") super.onActivityResult(requestCode, resultCode, data)
        val uri = data?.data
        if (resultCode != RESULT_OK || uri == null) return
        val kind = KINDS[requestCode] ?: return
        startImport(uri, kind, requestCode)
    }

    /** Copies the document on a background thread (DEMs and basemaps are large), with progress. */
    fun startImport(uri: Uri, kind: String, requestCode: Int) {
        if (importThread?.isAlive == true) {
            Toast.makeText(this, R.string.settings_import_busy, Toast.LENGTH_SHORT).show()
            return
        }
        progress.visibility = View.VISIBLE
        progress.progress = 0
        progressText.text = getString(R.string.settings_importing, kind)
        importThread = Thread({
            val result = try {
                Result.success(importFile(uri, kind) { done, total ->
                    main.post {
                        if (total > 0) progress.progress = (1000 * done / total).toInt()
                        progressText.text = getString(R.string.settings_import_progress, kind, done / 1_000_000.0, total / 1_000_000.0)
                    }
                })
            } catch (e: java.io.IOException) {
                Result.failure(e)
            } catch (e: SecurityException) {
                Result.failure(e)
            }
            main.post { importDone(requestCode, result) }
        }, "pdnav-import").apply { start() }
    }

    private fun importDone(requestCode: Int, result: Result<File>) {
        progress.visibility = View.GONE
        val file = result.getOrElse { e ->
            progressText.text = getString(R.string.settings_import_failed, e.message ?: e.toString())
            return
        }
        when (requestCode) {
            PICK_DEM -> settings.demPath = file.path
            PICK_GRAPH -> settings.graphPath = file.path
            PICK_BASEMAP -> settings.basemapPath = file.path
            PICK_NAV -> settings.navPath = file.path
        }
        fileLabels[requestCode]?.text = file.path
        progressText.text = getString(R.string.settings_imported, file.name)
    }

    /** Copies a picked document into files/data/<kind>/<display name>, reporting bytes copied. */
    private fun importFile(uri: Uri, kind: String, onProgress: (Long, Long) -> Unit): File {
        val (name, size) = describe(uri)
        val dir = File(filesDir, "data/$kind").apply { mkdirs() }
        val out = File(dir, (name ?: "$kind.bin").replace('/', '_'))
        val tmp = File(dir, out.name + ".part")
        val input = contentResolver.openInputStream(uri) ?: throw java.io.IOException("cannot open $uri")
        input.use { i ->
            tmp.outputStream().use { o ->
                val buf = ByteArray(1 shl 16)
                var done = 0L
                var reported = 0L
                while (true) {
                    val n = i.read(buf)
                    if (n < 0) break
                    o.write(buf, 0, n)
                    done += n
                    if (done - reported >= PROGRESS_STEP_BYTES) {
                        reported = done
                        onProgress(done, size)
                    }
                }
                onProgress(done, size)
            }
        }
        if (!tmp.renameTo(out)) throw java.io.IOException("cannot rename $tmp to $out")
        return out
    }

    private fun describe(uri: Uri): Pair<String?, Long> =
        contentResolver.query(uri, arrayOf(OpenableColumns.DISPLAY_NAME, OpenableColumns.SIZE), null, null, null)?.use { c ->
            if (c.moveToFirst()) {
                val name = if (c.isNull(0)) null else c.getString(0)
                val size = if (c.columnCount > 1 && !c.isNull(1)) c.getLong(1) else -1L
                name to size
            } else {
                null to -1L
            }
        } ?: (null to -1L)

    companion object {
        const val PICK_DEM = 11
        const val PICK_GRAPH = 12
        const val PICK_BASEMAP = 13
        const val PICK_NAV = 14
        private const val PROGRESS_STEP_BYTES = 1L shl 20
        val KINDS = mapOf(PICK_DEM to "dem", PICK_GRAPH to "graph", PICK_BASEMAP to "basemap", PICK_NAV to "nav")
    }
}
