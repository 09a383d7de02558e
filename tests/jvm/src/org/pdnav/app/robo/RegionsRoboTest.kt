package org.pdnav.app.robo

import android.content.Intent
import android.net.Uri
import android.os.Looper
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.nav.EngineKind
import org.pdnav.app.nav.NavEstimate
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.TestPaths
import org.pdnav.app.region.Place
import org.pdnav.app.region.PlaceStore
import org.pdnav.app.region.RegionException
import org.pdnav.app.region.RegionStore
import org.pdnav.app.walk.WalkerWords
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import java.io.File
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertFalse
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * Region packs (verify, install atomically, list, pick by position, delete), places per
 * region across sessions, and the walker's words (issue 29). No native code.
 */
@RunWith(RobolectricTestRunner::class)
class RegionsRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    private fun leftovers(store: RegionStore) = store.root.listFiles()?.filter { it.name.startsWith(".") }?.map { it.name } ?: emptyList()

    @Test
    fun aRegionIsVerifiedInstalledListedPickedAndDeleted() {
        val dir = TestPaths.scratch("regions-store")
        val store = RegionStore(File(dir, "files"))
        val files = RegionFixture.standIns(File(dir, "src"))
        val m = RegionFixture.manifest("Engolasters", 42.51, 1.55, 42.53, 1.59, files)
        val good = RegionFixture.pack(File(dir, "Engolasters.pdnav-region"), m, files.map { it.second })
        val info = good.inputStream().use { store.install(it, good.name) }
        assertEquals("Engolasters", info.name)
        assertEquals(42.53, info.bounds.northDeg)
        assertTrue(info.attribution.contains("© OpenStreetMap contributors"), info.attribution)
        assertTrue(File(info.demPath).isFile && File(info.graphPath).isFile && File(info.basemapPath).isFile)
        val listed = store.list().single()
        assertEquals(files.sumOf { it.second.length() } + File(listed.dir, "manifest.json").length(), listed.bytes, "size on disk")
        // a second, larger region around it: the smallest containing region is picked
        val big = RegionFixture.pack(File(dir, "Andorra.pdnav-region"),
            RegionFixture.manifest("Andorra", 42.40, 1.40, 42.66, 1.79, files), files.map { it.second })
        big.inputStream().use { store.install(it, big.name) }
        assertEquals(listOf("Andorra", "Engolasters"), store.list().map { it.name })
        assertEquals("Engolasters", store.containing(42.52, 1.57)?.name)
        assertEquals("Andorra", store.containing(42.45, 1.50)?.name)
        assertNull(store.containing(48.85, 2.35), "Paris is in no region")
        assertNull(store.containing(Double.NaN, 1.57))

        // bad packs: each refused with its reason, nothing half-installed, the installed one kept
        val damaged = files.map { it.second.copyTo(File(dir, "bad/" + it.second.name), overwrite = true) }
        damaged[1].writeBytes(damaged[1].readBytes().also { it[10] = (it[10] + 1).toByte() })
        val cases = listOf(
            "damaged" to RegionFixture.pack(File(dir, "b1.pdnav-region"), m, damaged),
            "bytes" to RegionFixture.pack(File(dir, "b2.pdnav-region"), m, listOf(files[0].second, files[1].second,
                File(dir, "short.mbtiles").apply { writeBytes(files[2].second.readBytes().copyOf(500)) }),
                listOf("dem.pdem", "graph.pgraph", "basemap.mbtiles")),
            "no manifest.json" to RegionFixture.pack(File(dir, "b3.pdnav-region"), null, files.map { it.second }),
            "missing" to RegionFixture.pack(File(dir, "b4.pdnav-region"), m, files.take(2).map { it.second }),
            "version 2" to RegionFixture.pack(File(dir, "b5.pdnav-region"),
                RegionFixture.manifest("Engolasters", 42.51, 1.55, 42.53, 1.59, files, version = 2), files.map { it.second }),
            "unexpected entry" to RegionFixture.pack(File(dir, "b6.pdnav-region"), m, files.map { it.second },
                listOf("../dem.pdem", "graph.pgraph", "basemap.mbtiles")),
            "not a region file" to File(dir, "b7.pdnav-region").apply { writeText("hello, not a zip") },
            "bounds" to RegionFixture.pack(File(dir, "b8.pdnav-region"),
                RegionFixture.manifest("Engolasters", 42.53, 1.55, 42.51, 1.59, files), files.map { it.second }),
        )
        for ((why, f) in cases) {
            val e = assertFailsWith<RegionException>(why) { f.inputStream().use { store.install(it, f.name) } }
            assertTrue(e.message!!.startsWith(f.name) && e.message!!.contains(why), "$why: ${e.message}")
            assertEquals(emptyList(), leftovers(store), "$why: nothing half-installed")
            val kept = assertNotNull(store.find("Engolasters"), "$why: the installed region is kept")
            assertEquals(RegionFixture.sha256(files[1].second), RegionFixture.sha256(File(kept.graphPath)), "$why: its files untouched")
        }
        // a re-import replaces the region whole
        good.inputStream().use { store.install(it, good.name) }
        assertEquals(2, store.list().size)
        assertTrue(store.delete("Engolasters"))
        assertFalse(store.delete("Engolasters"))
        assertEquals(listOf("Andorra"), store.list().map { it.name })
        assertFalse(store.delete("../files"), "no path escapes the regions folder")
    }

    @Test
    fun placesPersistPerRegionAcrossSessions() {
        val dir = TestPaths.scratch("places")
        val a = PlaceStore(dir, "Engolasters")
        a.add(Place("Start 09:41", 42.5218, 1.5716, Place.START, 1000))
        a.add(Place("Hut", 42.5301, 1.5650, Place.SAVED, 2000))
        a.add(Place("Checkpoint 09:50", 42.5230, 1.5720, Place.CHECKPOINT, 3000))
        PlaceStore(dir, "Andorra").add(Place("Car park", 42.50, 1.52, Place.SAVED, 4000))
        // a new session (new store objects) sees the same places, per region
        val again = PlaceStore(dir, "Engolasters").list()
        assertEquals(listOf("Start 09:41", "Hut", "Checkpoint 09:50"), again.map { it.name })
        assertEquals(listOf(Place.START, Place.SAVED, Place.CHECKPOINT), again.map { it.kind })
        assertEquals(42.5301, again[1].latDeg)
        assertEquals(listOf("Car park"), PlaceStore(dir, "Andorra").list().map { it.name })
        assertEquals(emptyList(), PlaceStore(dir, null).list())
        assertTrue(PlaceStore(dir, "Engolasters").remove(again[1]))
        assertEquals(2, PlaceStore(dir, "Engolasters").list().size)
        assertFailsWith<IllegalArgumentException> { a.add(Place("bad", Double.NaN, 1.0, Place.SAVED, 0)) }
        // a damaged file reads as no places, never a crash
        a.file.writeText("{not json")
        assertEquals(emptyList(), a.list())
    }

    private fun out(engine: EngineKind, status: Int, sigmaM: Double, withRoute: Boolean = false): NavOutput {
        val v = sigmaM * sigmaM / 2
        val e = NavEstimate(1L, engine.ordinal, status, "engine internals: terrain PF 500 particles", 42.52, 1.57, 1600.0,
            0.0, 0.0, v, 0.0, v, 3.0)
        return NavOutput(e, arrayOf(e), 10, DoubleArray(0))
    }

    @Test
    fun theWalkersWordsForEachSource() {
        assertEquals("Satellites", WalkerWords.source(out(EngineKind.GNSS, 1, 4.0), true))
        assertEquals("Satellites (weak signal)", WalkerWords.source(out(EngineKind.GNSS, 2, 12.0), true))
        assertEquals("No satellites: terrain and paths", WalkerWords.source(out(EngineKind.TERRAIN, 2, 20.0), graphLoaded = true))
        assertEquals("No satellites: terrain", WalkerWords.source(out(EngineKind.TERRAIN, 2, 20.0), graphLoaded = false))
        assertEquals("No satellites: paths", WalkerWords.source(out(EngineKind.ROUTE, 2, 9.0), true))
        assertEquals("Dead reckoning only", WalkerWords.source(out(EngineKind.DEAD_RECKONING, 2, 40.0), true))
        assertEquals("Waiting for a first position", WalkerWords.source(null, true))
        // the GNSS-only mode after 3 s without an epoch: lost, its last position kept, not "very good"
        assertEquals("Position lost: no signal", WalkerWords.source(out(EngineKind.GNSS, 4, 2.0), true))
        assertEquals("No position now", WalkerWords.position(out(EngineKind.GNSS, 4, 2.0).estimate))
        assertEquals("±4 m, very good", WalkerWords.position(out(EngineKind.GNSS, 1, 4.0).estimate))
        assertEquals("±8 m, good", WalkerWords.position(8.2))
        assertEquals("±4 m, very good", WalkerWords.position(4.0))
        assertEquals("±15 m, good", WalkerWords.position(15.3), "the word of the number shown")
        assertEquals("±16 m, fair", WalkerWords.position(15.5))
        assertEquals("±120 m, poor", WalkerWords.position(120.0))
        assertEquals("±1.50 km, very poor", WalkerWords.position(1500.0))
        assertEquals("Facing north-east (47°)", WalkerWords.heading(Math.toRadians(47.0)))
        assertEquals("Facing north (0°)", WalkerWords.heading(Math.toRadians(359.7)))
        assertEquals("Facing west (270°)", WalkerWords.heading(Math.toRadians(-90.0)))
        assertEquals("Walked 1.24 km in 0:23:10", WalkerWords.walked(1240.0, (23 * 60 + 10) * 1_000_000_000L))
    }

    @Test
    fun openWithARegionFileInstallsItAndABadOneIsRefusedOnScreen() {
        val dir = TestPaths.scratch("regions-openwith")
        val files = RegionFixture.standIns(File(dir, "src"))
        val good = RegionFixture.pack(File(dir, "Engolasters.pdnav-region"),
            RegionFixture.manifest("Engolasters", 42.51, 1.55, 42.53, 1.59, files), files.map { it.second })
        val view = Intent(Intent.ACTION_VIEW, Uri.fromFile(good))
        val c = org.robolectric.Robolectric.buildActivity(org.pdnav.app.ui.RegionsActivity::class.java, view).setup()
        c.get().importThread?.join(20_000)
        shadowOf(Looper.getMainLooper()).idle()
        val status = c.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.regions_status).text.toString()
        assertTrue(status.startsWith("Installed Engolasters"), status)
        assertEquals("Engolasters", RegionStore(app.filesDir).find("Engolasters")?.name)
        val prefs = app.getSharedPreferences(org.pdnav.app.ui.AppSettings.PREFS, android.content.Context.MODE_PRIVATE)
        assertEquals("Engolasters", org.pdnav.app.ui.AppSettings(prefs).lastRegion, "the map opens on the new region")
        // a damaged one: the reason on screen, the installed region kept
        val bad = File(dir, "broken.pdnav-region").apply { writeBytes(good.readBytes().copyOf(good.length().toInt() / 2)) }
        c.get().startImport(Uri.fromFile(bad))
        c.get().importThread?.join(20_000)
        shadowOf(Looper.getMainLooper()).idle()
        val refused = c.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.regions_status).text.toString()
        assertTrue(refused.startsWith("Not installed: broken.pdnav-region"), refused)
        assertEquals(listOf("Engolasters"), RegionStore(app.filesDir).list().map { it.name })
    }
}
