package org.pdnav.app.ui

import android.app.Activity
import android.content.Context
import android.content.Intent
import android.net.Uri
import android.os.Bundle
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
 * Start screen / settings: start uncertainty (the point itself is a long-press on the map, or
 * the last GNSS fix), user height and sex (step length), particle count, engine, and the DEM,
 * walkway graph, basemap and RINEX navigation files, imported through the system file picker
 * (ACTION_OPEN_DOCUMENT) and copied into app storage.
 */
class SettingsActivity : Activity() {
    private lateinit var settings: AppSettings
    private lateinit var heightField: EditText
    private lateinit var female: CheckBox
    private lateinit var particles: EditText
    private lateinit var engine: Spinner
    private lateinit var sigma: EditText
    private val fileLabels = mutableMapOf<Int, TextView>()

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
        setPadding(32, 32, 32, 32)
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
        addView(Views.button(context, android.view.View.NO_ID, getString(R.string.settings_start_last_fix)) {
            settings.useLastFix()
            Toast.makeText(context, R.string.settings_start_last_fix, Toast.LENGTH_SHORT).show()
        })
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
        settings.engine = AppSettings.ENGINES[engine.selectedItemPosition.coerceIn(0, AppSettings.ENGINES.size - 1)]
        finish()
    }

    @Deprecated("framework API (no AndroidX activity-result here)")
    override fun onActivityResult(requestCode: Int, resultCode: Int, data: Intent?) {
        @Suppress("DEPRECATION") super.onActivityResult(requestCode, resultCode, data)
        val uri = data?.data
        if (resultCode != RESULT_OK || uri == null) return
        try {
            val file = importFile(uri, KINDS[requestCode] ?: return)
            when (requestCode) {
                PICK_DEM -> settings.demPath = file.path
                PICK_GRAPH -> settings.graphPath = file.path
                PICK_BASEMAP -> settings.basemapPath = file.path
                PICK_NAV -> settings.navPath = file.path
            }
            fileLabels[requestCode]?.text = file.path
        } catch (e: java.io.IOException) {
            Toast.makeText(this, "import failed: ${e.message}", Toast.LENGTH_LONG).show()
        }
    }

    /** Copies a picked document into files/data/<kind>/<display name>. */
    private fun importFile(uri: Uri, kind: String): File {
        val name = displayName(uri) ?: "$kind.bin"
        val dir = File(filesDir, "data/$kind").apply { mkdirs() }
        val out = File(dir, name.replace('/', '_'))
        val input = contentResolver.openInputStream(uri) ?: throw java.io.IOException("cannot open $uri")
        input.use { i -> out.outputStream().use { o -> i.copyTo(o) } }
        return out
    }

    private fun displayName(uri: Uri): String? =
        contentResolver.query(uri, arrayOf(OpenableColumns.DISPLAY_NAME), null, null, null)?.use { c ->
            if (c.moveToFirst()) c.getString(0) else null
        }

    companion object {
        const val PICK_DEM = 11
        const val PICK_GRAPH = 12
        const val PICK_BASEMAP = 13
        const val PICK_NAV = 14
        private val KINDS = mapOf(PICK_DEM to "dem", PICK_GRAPH to "graph", PICK_BASEMAP to "basemap", PICK_NAV to "nav")
    }
}
