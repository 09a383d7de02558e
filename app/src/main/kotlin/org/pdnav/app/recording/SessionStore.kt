package org.pdnav.app.recording

import android.content.Context
import android.content.Intent
import android.net.Uri
import java.io.File
import java.text.SimpleDateFormat
import java.util.Date
import java.util.Locale
import java.util.TimeZone

/** Recorded sessions: one log file each in the app's storage, newest first. */
class SessionStore(private val context: Context) {
    val dir: File
        get() = File(context.getExternalFilesDir(null) ?: context.filesDir, "sessions").apply { mkdirs() }

    fun list(): List<File> =
        (dir.listFiles { f -> f.isFile && f.name.endsWith(SUFFIX) } ?: emptyArray()).sortedByDescending { it.name }

    /** A new file named after the UTC start time, e.g. pdnav_20261123_164500.txt. */
    fun newSessionFile(nowMs: Long = System.currentTimeMillis()): File {
        val fmt = SimpleDateFormat("yyyyMMdd_HHmmss", Locale.US).apply { timeZone = TimeZone.getTimeZone("UTC") }
        var f = File(dir, "pdnav_${fmt.format(Date(nowMs))}$SUFFIX")
        var k = 1
        while (f.exists()) f = File(dir, "pdnav_${fmt.format(Date(nowMs))}_${k++}$SUFFIX")
        return f
    }

    /** content:// URI of a session served by [SessionProvider]. */
    fun uriFor(file: File): Uri = Uri.parse("content://${SessionProvider.AUTHORITY}/${Uri.encode(file.name)}")

    /** A chooser that shares the session log (read permission granted to the receiver). */
    fun shareIntent(file: File): Intent {
        val send = Intent(Intent.ACTION_SEND).apply {
            type = "text/plain"
            putExtra(Intent.EXTRA_STREAM, uriFor(file))
            putExtra(Intent.EXTRA_SUBJECT, file.name)
            addFlags(Intent.FLAG_GRANT_READ_URI_PERMISSION)
        }
        return Intent.createChooser(send, file.name)
    }

    companion object {
        const val SUFFIX = ".txt"
    }
}
