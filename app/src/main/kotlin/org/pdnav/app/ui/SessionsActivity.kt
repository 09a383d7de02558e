package org.pdnav.app.ui

import android.app.Activity
import android.app.AlertDialog
import android.content.Intent
import android.os.Bundle
import android.view.Gravity
import android.view.View
import android.view.ViewGroup
import android.widget.BaseAdapter
import android.widget.FrameLayout
import android.widget.LinearLayout
import android.widget.ListView
import android.widget.TextView
import android.widget.Toast
import org.pdnav.app.R
import org.pdnav.app.recording.SessionStore
import java.io.File
import java.io.IOException

/**
 * The recorded sessions, newest first, each with Share (raw log), Zip (share a zip), Export
 * (copy to a folder the user picks, which survives uninstalling), Replay and Delete; a text
 * when there is none.
 */
class SessionsActivity : Activity() {
    private lateinit var store: SessionStore
    private var files: List<File> = emptyList()
    private lateinit var list: ListView
    private lateinit var empty: TextView
    private var exporting: File? = null

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        store = SessionStore(this)
        list = ListView(this).apply { id = R.id.sessions_list }
        empty = TextView(this).apply {
            id = R.id.sessions_empty
            text = getString(R.string.sessions_empty)
            gravity = Gravity.CENTER
        }
        // the empty view must be in the hierarchy for ListView to show it
        val root = FrameLayout(this)
        root.addView(list, FrameLayout.LayoutParams(-1, -1))
        root.addView(empty, FrameLayout.LayoutParams(-1, -1))
        list.emptyView = empty
        Views.applySystemBarInsets(root, list, list)
        setContentView(root)
        exporting = savedInstanceState?.getString(STATE_EXPORT)?.let(::File)
    }

    override fun onSaveInstanceState(outState: Bundle) {
        super.onSaveInstanceState(outState)
        exporting?.let { outState.putString(STATE_EXPORT, it.path) }
    }

    override fun onResume() {
        super.onResume()
        refresh()
    }

    private fun refresh() {
        files = store.list()
        list.adapter = Adapter()
    }

    fun share(f: File) = startActivity(store.shareIntent(f))

    fun shareZip(f: File) {
        try {
            startActivity(store.shareIntent(store.zip(f)))
        } catch (e: IOException) {
            Toast.makeText(this, getString(R.string.error_generic, e.message ?: ""), Toast.LENGTH_LONG).show()
        }
    }

    fun export(f: File) {
        exporting = f
        @Suppress("DEPRECATION") startActivityForResult(store.exportIntent(f), REQUEST_EXPORT)
    }

    fun delete(f: File, confirm: Boolean = true) {
        if (!confirm) {
            store.delete(f)
            refresh()
            return
        }
        AlertDialog.Builder(this).setMessage(getString(R.string.sessions_delete_confirm, f.name))
            .setPositiveButton(R.string.action_delete) { _, _ -> delete(f, confirm = false) }
            .setNegativeButton(android.R.string.cancel, null)
            .show()
    }

    fun replay(f: File) {
        startActivity(Intent(this, MainActivity::class.java)
            .putExtra(MainActivity.EXTRA_REPLAY, f.path)
            .addFlags(Intent.FLAG_ACTIVITY_CLEAR_TOP or Intent.FLAG_ACTIVITY_SINGLE_TOP))
    }

    @Deprecated("framework API (no AndroidX activity-result here)")
    override fun onActivityResult(requestCode: Int, resultCode: Int, data: Intent?) {
        @Suppress("DEPRECATION") super.onActivityResult(requestCode, resultCode, data)
        val uri = data?.data
        val f = exporting
        if (requestCode != REQUEST_EXPORT || resultCode != RESULT_OK || uri == null || f == null) return
        exporting = null
        Thread({
            val msg = try {
                store.export(f, uri)
                getString(R.string.sessions_exported, f.name)
            } catch (e: IOException) {
                getString(R.string.error_generic, e.message ?: "")
            }
            runOnUiThread { Toast.makeText(this, msg, Toast.LENGTH_LONG).show() }
        }, "pdnav-export").start()
    }

    private inner class Adapter : BaseAdapter() {
        override fun getCount() = files.size
        override fun getItem(position: Int) = files[position]
        override fun getItemId(position: Int) = position.toLong()

        override fun getView(position: Int, convertView: View?, parent: ViewGroup?): View {
            val f = files[position]
            val ctx = this@SessionsActivity
            val name = TextView(ctx).apply { text = "${f.name}  (${f.length() / 1024} KiB)" }
            val share = Views.button(ctx, View.NO_ID, getString(R.string.action_share)) { share(f) }
            val zip = Views.button(ctx, View.NO_ID, getString(R.string.action_zip)) { shareZip(f) }
            val export = Views.button(ctx, View.NO_ID, getString(R.string.action_export)) { export(f) }
            val replay = Views.button(ctx, View.NO_ID, getString(R.string.action_replay)) { replay(f) }
            val delete = Views.button(ctx, View.NO_ID, getString(R.string.action_delete)) { delete(f) }
            return LinearLayout(ctx).apply {
                orientation = LinearLayout.VERTICAL
                val p = Views.dp(ctx, 8)
                setPadding(p * 2, p, p * 2, p)
                addView(name)
                addView(Views.row(ctx, share, zip, export))
                addView(Views.row(ctx, replay, delete))
            }
        }
    }

    companion object {
        const val REQUEST_EXPORT = 21
        private const val STATE_EXPORT = "exporting"
    }
}
