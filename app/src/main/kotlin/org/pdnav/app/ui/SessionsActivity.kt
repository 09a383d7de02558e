package org.pdnav.app.ui

import android.app.Activity
import android.content.Intent
import android.os.Bundle
import android.view.View
import android.view.ViewGroup
import android.widget.BaseAdapter
import android.widget.LinearLayout
import android.widget.ListView
import android.widget.TextView
import org.pdnav.app.R
import org.pdnav.app.recording.SessionStore
import java.io.File

/** The recorded sessions, newest first, each with Share and Replay. */
class SessionsActivity : Activity() {
    private lateinit var store: SessionStore
    private var files: List<File> = emptyList()
    private lateinit var list: ListView

    override fun onCreate(savedInstanceState: Bundle?) {
        super.onCreate(savedInstanceState)
        store = SessionStore(this)
        list = ListView(this).apply { id = R.id.sessions_list }
        list.emptyView = TextView(this).apply { text = getString(R.string.sessions_empty) }
        setContentView(list)
    }

    override fun onResume() {
        super.onResume()
        files = store.list()
        list.adapter = Adapter()
    }

    fun share(f: File) = startActivity(store.shareIntent(f))

    fun replay(f: File) {
        startActivity(Intent(this, MainActivity::class.java)
            .putExtra(MainActivity.EXTRA_REPLAY, f.path)
            .addFlags(Intent.FLAG_ACTIVITY_CLEAR_TOP or Intent.FLAG_ACTIVITY_SINGLE_TOP))
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
            val replay = Views.button(ctx, View.NO_ID, getString(R.string.action_replay)) { replay(f) }
            return LinearLayout(ctx).apply {
                orientation = LinearLayout.VERTICAL
                setPadding(24, 16, 24, 16)
                addView(name)
                addView(Views.row(ctx, share, replay))
            }
        }
    }
}
