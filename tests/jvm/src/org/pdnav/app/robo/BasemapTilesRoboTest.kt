package org.pdnav.app.robo

import android.graphics.drawable.BitmapDrawable
import android.graphics.drawable.Drawable
import android.os.Looper
import org.junit.Test
import org.junit.runner.RunWith
import org.osmdroid.config.Configuration
import org.osmdroid.tileprovider.MapTileProviderArray
import org.osmdroid.tileprovider.modules.ArchiveFileFactory
import org.osmdroid.tileprovider.modules.MBTilesFileArchive
import org.osmdroid.tileprovider.modules.MapTileFileArchiveProvider
import org.osmdroid.tileprovider.tilesource.XYTileSource
import org.osmdroid.tileprovider.util.SimpleRegisterReceiver
import org.osmdroid.util.MapTileIndex
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.GraphicsMode
import org.robolectric.annotation.LooperMode
import java.io.File
import kotlin.math.PI
import kotlin.math.asinh
import kotlin.math.floor
import kotlin.math.tan
import kotlin.test.assertEquals
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * The dem-tools basemap (MBTiles, rendered by Mapnik from the real Andorra data) opens in
 * osmdroid's own tile machinery on the host: ArchiveFileFactory picks MBTilesFileArchive, and a
 * MapTileProviderArray over a MapTileFileArchiveProvider delivers decoded 256 px tiles whose
 * pixels are the basemap's (water colour over the lake at every zoom). Native graphics so that
 * BitmapFactory really decodes the PNGs.
 */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
@GraphicsMode(GraphicsMode.Mode.NATIVE)
class BasemapTilesRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    private fun tileOf(lat: Double, lon: Double, z: Int): Triple<Int, Int, Pair<Int, Int>> {
        val n = 256.0 * (1 shl z)
        val gx = (lon + 180.0) / 360.0 * n
        val gy = (1.0 - asinh(tan(Math.toRadians(lat))) / PI) / 2.0 * n
        val x = floor(gx / 256).toInt()
        val y = floor(gy / 256).toInt()
        return Triple(x, y, (gx - 256.0 * x).toInt() to (gy - 256.0 * y).toInt())
    }

    private fun await(provider: MapTileProviderArray, index: Long, timeoutMs: Long): Drawable? {
        val end = System.currentTimeMillis() + timeoutMs
        while (System.currentTimeMillis() < end) {
            val d = provider.getMapTile(index)
            if (d != null) return d
            shadowOf(Looper.getMainLooper()).idle()
            Thread.sleep(20)
        }
        return null
    }

    @Test
    fun mbtilesLoadThroughMapTileProviderArray() {
        val file = BasemapFixture.mbtiles()
        Configuration.getInstance().apply {
            userAgentValue = app.packageName
            osmdroidBasePath = File(app.filesDir, "osmdroid")
            osmdroidTileCache = File(app.cacheDir, "osmdroid-tiles")
        }
        val archive = assertNotNull(ArchiveFileFactory.getArchiveFile(file), "osmdroid cannot open $file")
        assertTrue(archive is MBTilesFileArchive, "ArchiveFileFactory chose ${archive.javaClass.name}")
        val source = XYTileSource("pdnav-basemap", BasemapFixture.MIN_ZOOM, BasemapFixture.MAX_ZOOM, 256, ".png", arrayOf())
        val receiver = SimpleRegisterReceiver(app)
        val provider = MapTileProviderArray(source, receiver,
            arrayOf(MapTileFileArchiveProvider(receiver, source, arrayOf(archive))))
        try {
            for (z in BasemapFixture.MIN_ZOOM..BasemapFixture.MAX_ZOOM) {
                var water = 0
                for ((lat, lon) in BasemapFixture.LAKE_POINTS) {
                    val (x, y, px) = tileOf(lat, lon, z)
                    val d = assertNotNull(await(provider, MapTileIndex.getTileIndex(z, x, y), 20_000),
                        "z$z tile $x/$y over the lake not delivered by MapTileProviderArray")
                    val bmp = (d as BitmapDrawable).bitmap
                    assertEquals(256, bmp.width)
                    assertEquals(256, bmp.height)
                    if (BasemapFixture.close(bmp.getPixel(px.first, px.second), BasemapFixture.WATER, 12)) water++
                }
                assertTrue(water >= 3, "z$z: water colour at $water of ${BasemapFixture.LAKE_POINTS.size} lake points")
            }
            // a tile the basemap does not hold (Barcelona, z16): the archive has nothing and the
            // provider array delivers nothing, offline
            val (bx, by, _) = tileOf(41.3874, 2.1686, 16)
            assertNull(archive.getInputStream(source, MapTileIndex.getTileIndex(16, bx, by)))
            assertNull(await(provider, MapTileIndex.getTileIndex(16, bx, by), 1_000))
        } finally {
            provider.detach()
        }
    }
}
