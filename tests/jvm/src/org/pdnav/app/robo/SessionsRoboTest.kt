package org.pdnav.app.robo

import android.content.Context
import android.content.Intent
import android.net.Uri
import android.widget.CheckBox
import android.widget.EditText
import android.widget.ListView
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.R
import org.pdnav.app.recording.SessionProvider
import org.pdnav.app.recording.SessionStore
import org.pdnav.app.ui.AppSettings
import org.pdnav.app.ui.MainActivity
import org.pdnav.app.ui.SessionsActivity
import org.pdnav.app.ui.SettingsActivity
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.LooperMode
import java.io.FileNotFoundException
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertNotNull
import kotlin.test.assertTrue

/** Sessions list (share through the app's provider, replay in the map screen) and settings. */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
class SessionsRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    @Test
    fun sessionsAreListedNewestFirstSharedAndReplayed() {
        val store = SessionStore(app)
        val older = store.newSessionFile(1_700_000_000_000L).apply { writeText("# old\n") }
        val newer = store.newSessionFile(1_700_000_100_000L).apply { writeText("# new session\n") }
        assertEquals(listOf(newer, older), store.list())

        val activity = Robolectric.buildActivity(SessionsActivity::class.java).setup().get()
        assertEquals(2, activity.findViewById<ListView>(R.id.sessions_list).adapter.count)

        activity.share(newer)
        val chooser = assertNotNull(shadowOf(activity).nextStartedActivity)
        assertEquals(Intent.ACTION_CHOOSER, chooser.action)
        @Suppress("DEPRECATION") val send = assertNotNull(chooser.getParcelableExtra<Intent>(Intent.EXTRA_INTENT))
        assertEquals(Intent.ACTION_SEND, send.action)
        assertEquals("text/csv", send.type, "a log is data, not text to paste")
        @Suppress("DEPRECATION") val uri = assertNotNull(send.getParcelableExtra<Uri>(Intent.EXTRA_STREAM))
        assertEquals(SessionProvider.AUTHORITY, uri.authority)
        assertTrue(send.flags and Intent.FLAG_GRANT_READ_URI_PERMISSION != 0, "read permission granted to the receiver")

        // the provider serves the file read-only and nothing outside the sessions folder
        Robolectric.setupContentProvider(SessionProvider::class.java, SessionProvider.AUTHORITY)
        val text = app.contentResolver.openInputStream(uri)?.use { it.readBytes().decodeToString() }
        assertEquals("# new session\n", text)
        assertFailsWith<FileNotFoundException> {
            app.contentResolver.openInputStream(Uri.parse("content://${SessionProvider.AUTHORITY}/..%2Fshared_prefs%2Fpdnav.xml"))
        }

        activity.replay(older)
        val replay = assertNotNull(shadowOf(activity).nextStartedActivity)
        assertEquals(MainActivity::class.java.name, replay.component?.className)
        assertEquals(older.path, replay.getStringExtra(MainActivity.EXTRA_REPLAY))
    }

    @Test
    fun noSessionsShowsTheAttachedEmptyViewAndDeleteZipExportWork() {
        SessionStore(app).list().forEach { it.delete() }
        val controller = Robolectric.buildActivity(SessionsActivity::class.java).setup()
        val activity = controller.get()
        val list = activity.findViewById<ListView>(R.id.sessions_list)
        val empty = assertNotNull(activity.findViewById<android.widget.TextView>(R.id.sessions_empty), "empty view in the hierarchy")
        assertEquals(empty, list.emptyView)
        assertEquals(android.view.View.VISIBLE, empty.visibility, "empty view shown")

        val store = SessionStore(app)
        val f = store.newSessionFile(1_700_000_200_000L).apply { writeText("Meta,1,Device,x\n") }
        controller.pause().resume()
        assertEquals(1, list.adapter.count)
        assertEquals(android.view.View.GONE, empty.visibility)

        activity.shareZip(f)
        val chooser = assertNotNull(shadowOf(activity).nextStartedActivity)
        @Suppress("DEPRECATION") val send = assertNotNull(chooser.getParcelableExtra<Intent>(Intent.EXTRA_INTENT))
        assertEquals("application/zip", send.type)
        val zip = java.io.File(store.dir, f.name.removeSuffix(".txt") + ".zip")
        java.util.zip.ZipFile(zip).use { z -> assertEquals(f.readText(), z.getInputStream(z.getEntry(f.name)).readBytes().decodeToString()) }

        activity.export(f)
        val create = assertNotNull(shadowOf(activity).nextStartedActivity)
        assertEquals(Intent.ACTION_CREATE_DOCUMENT, create.action)
        assertEquals(f.name, create.getStringExtra(Intent.EXTRA_TITLE))

        activity.delete(f, confirm = false)
        assertTrue(!f.exists())
        assertEquals(0, list.adapter.count)
    }

    @Test
    fun settingsAreValidatedAndReachTheNavigatorConfig() {
        val activity = Robolectric.buildActivity(SettingsActivity::class.java).setup().get()
        activity.findViewById<EditText>(R.id.settings_height).setText("1.62")
        activity.findViewById<CheckBox>(R.id.settings_female).isChecked = true
        activity.findViewById<EditText>(R.id.settings_particles).setText("800")
        activity.findViewById<EditText>(R.id.settings_sigma).setText("12.5")
        activity.save()
        val cfg = AppSettings(app.getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE)).navigatorConfig()
        assertEquals(1.62, cfg.userHeightM, 1e-6)
        assertTrue(cfg.userFemale)
        assertEquals(800, cfg.particles)
        assertEquals(12.5, cfg.startSigmaM, 1e-6)
        assertTrue(cfg.startLatDeg.isNaN(), "no declared start: first GNSS fix")
        assertTrue(activity.isFinishing)

        val again = Robolectric.buildActivity(SettingsActivity::class.java).setup().get()
        again.findViewById<EditText>(R.id.settings_particles).setText("3")  // out of range: refused
        again.save()
        assertEquals(800, AppSettings(app.getSharedPreferences(AppSettings.PREFS, Context.MODE_PRIVATE)).particles)
        assertTrue(!again.isFinishing)
    }
}
