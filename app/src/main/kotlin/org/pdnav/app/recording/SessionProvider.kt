package org.pdnav.app.recording

import android.content.ContentProvider
import android.content.ContentValues
import android.database.Cursor
import android.database.MatrixCursor
import android.net.Uri
import android.os.ParcelFileDescriptor
import android.provider.OpenableColumns
import java.io.File
import java.io.FileNotFoundException

/**
 * Serves recorded session files read-only to the app chosen in the share sheet
 * (the framework has no FileProvider without AndroidX). Only plain file names inside the
 * sessions folder resolve; anything else is FileNotFoundException.
 */
class SessionProvider : ContentProvider() {
    override fun onCreate() = true

    private fun fileFor(uri: Uri): File {
        val ctx = context ?: throw FileNotFoundException("no context")
        val name = uri.lastPathSegment ?: throw FileNotFoundException("no file name in $uri")
        if (name.contains('/') || name.startsWith(".")) throw FileNotFoundException("bad session name $name")
        val f = File(SessionStore(ctx).dir, name)
        if (!f.isFile || !(name.endsWith(SessionStore.SUFFIX) || name.endsWith(SessionStore.ZIP_SUFFIX))) {
            throw FileNotFoundException("no session $name")
        }
        return f
    }

    override fun openFile(uri: Uri, mode: String): ParcelFileDescriptor {
        if (mode != "r") throw FileNotFoundException("sessions are read-only")
        return ParcelFileDescriptor.open(fileFor(uri), ParcelFileDescriptor.MODE_READ_ONLY)
    }

    override fun query(uri: Uri, projection: Array<out String>?, selection: String?, selectionArgs: Array<out String>?, sortOrder: String?): Cursor {
        val f = fileFor(uri)
        val cols = arrayOf(OpenableColumns.DISPLAY_NAME, OpenableColumns.SIZE)
        return MatrixCursor(cols, 1).apply { addRow(arrayOf<Any>(f.name, f.length())) }
    }

    override fun getType(uri: Uri): String = mimeType(uri.lastPathSegment ?: "")
    override fun insert(uri: Uri, values: ContentValues?): Uri? = null
    override fun delete(uri: Uri, selection: String?, selectionArgs: Array<out String>?) = 0
    override fun update(uri: Uri, values: ContentValues?, selection: String?, selectionArgs: Array<out String>?) = 0

    companion object {
        const val AUTHORITY = "org.pdnav.app.sessions"

        /**
         * A session log is a CSV-like data file, not text to paste into a message
         * (text/plain makes chat apps inline it): text/csv; a zip is application/zip.
         */
        fun mimeType(name: String): String = if (name.endsWith(SessionStore.ZIP_SUFFIX)) "application/zip" else "text/csv"
    }
}
