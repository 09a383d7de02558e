package org.pdnav.app.recording

import android.content.Context
import android.content.Intent
import android.net.Uri
import java.io.File
import java.io.IOException
import java.io.OutputStream
import java.io.RandomAccessFile
import java.text.SimpleDateFormat
import java.util.Date
import java.util.Locale
import java.util.TimeZone
import java.util.zip.ZipEntry
import java.util.zip.ZipOutputStream

/**
 * Recorded sessions: one log file each in the app's storage, newest first; share (raw or
 * zipped), export to a folder the user picks (survives uninstalling), delete; the marker of
 * the recording in progress, so a restarted process finds a session a kill interrupted.
 */
class SessionStore(private val context: Context) {
    val dir: File
        get() = File(context.getExternalFilesDir(null) ?: context.filesDir, "sessions").apply { mkdirs() }

    private val activeMarker: File get() = File(dir, ACTIVE_MARKER)

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

    /** Remembers that [file] is being recorded (cleared by a clean stop). */
    fun markActive(file: File) = activeMarker.writeText(file.name)

    fun clearActive() {
        activeMarker.delete()
    }

    /**
     * After a restart: the recording a killed process left open gets an end marker
     * (`Meta,,SessionEnd,interrupted`; a torn last line is closed first, the reader skips it)
     * and is returned, once. Null when the last session ended cleanly.
     */
    fun recoverInterrupted(): File? {
        val marker = activeMarker
        if (!marker.isFile) return null
        val name = try {
            marker.readText().trim()
        } catch (e: IOException) {
            ""
        }
        marker.delete()
        val f = File(dir, name)
        if (name.isEmpty() || name.contains('/') || !f.isFile) return null
        return try {
            appendEndMarker(f, "interrupted")
            f
        } catch (e: IOException) {
            null
        }
    }

    /** Appends a `SessionEnd` Meta line (no time: the reader gives it the latest line's time). */
    fun appendEndMarker(f: File, reason: String) {
        RandomAccessFile(f, "rw").use { raf ->
            val len = raf.length()
            val torn = len > 0 && run {
                raf.seek(len - 1)
                raf.read() != '\n'.code
            }
            raf.seek(len)
            val line = (if (torn) "\n" else "") + "Meta,,SessionEnd,$reason\n"
            raf.write(line.toByteArray(Charsets.UTF_8))
            raf.fd.sync()
        }
    }

    /** Deletes a session file (only files of the sessions folder). */
    fun delete(file: File): Boolean = file.parentFile == dir && file.delete()

    /** content:// URI of a session served by [SessionProvider]. */
    fun uriFor(file: File): Uri = Uri.parse("content://${SessionProvider.AUTHORITY}/${Uri.encode(file.name)}")

    /** A chooser that shares the session log (read permission granted to the receiver). */
    fun shareIntent(file: File): Intent {
        val send = Intent(Intent.ACTION_SEND).apply {
            type = SessionProvider.mimeType(file.name)
            putExtra(Intent.EXTRA_STREAM, uriFor(file))
            putExtra(Intent.EXTRA_SUBJECT, file.name)
            addFlags(Intent.FLAG_GRANT_READ_URI_PERMISSION)
        }
        return Intent.createChooser(send, file.name)
    }

    /** Zips [file] into the sessions folder (name.zip, replacing an older zip); returns the zip. */
    fun zip(file: File): File {
        val out = File(dir, file.name.removeSuffix(SUFFIX) + ZIP_SUFFIX)
        ZipOutputStream(out.outputStream().buffered()).use { z ->
            z.putNextEntry(ZipEntry(file.name))
            file.inputStream().use { it.copyTo(z) }
            z.closeEntry()
        }
        return out
    }

    /** ACTION_CREATE_DOCUMENT: the user picks a visible folder (Downloads, SD card, Drive). */
    fun exportIntent(file: File): Intent = Intent(Intent.ACTION_CREATE_DOCUMENT)
        .addCategory(Intent.CATEGORY_OPENABLE)
        .setType(SessionProvider.mimeType(file.name))
        .putExtra(Intent.EXTRA_TITLE, file.name)

    /** Copies [file] into the document the user created. */
    fun export(file: File, target: Uri) {
        val os: OutputStream = context.contentResolver.openOutputStream(target) ?: throw IOException("cannot write $target")
        os.use { o -> file.inputStream().use { it.copyTo(o) } }
    }

    companion object {
        const val SUFFIX = ".txt"
        const val ZIP_SUFFIX = ".zip"
        const val ACTIVE_MARKER = ".recording"
    }
}
