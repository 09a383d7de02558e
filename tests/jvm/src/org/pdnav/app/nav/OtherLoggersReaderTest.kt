package org.pdnav.app.nav

import org.junit.Test
import java.io.File
import java.io.IOException
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertTrue

/**
 * The app's replay reader (NativeLogReader -> JNI readerOpen -> io::open_sample_source) takes
 * the other loggers' recordings: the shared Sensor Logger walk (a folder) reads whole, every
 * row of its sensor files a sample, nothing skipped; a file that is no recording is an
 * IOException saying what was expected.
 */
class OtherLoggersReaderTest {
    private fun dataRows(f: File) = f.readLines().count { it.isNotBlank() } - 1

    @Test
    fun sensorLoggerFolderReadsThroughTheBridge() {
        val dir = TestPaths.sharedData("walk-ethz-sensorlogger/2023-03-17_15-50-47/Metadata.csv").parentFile
        val kinds = HashMap<Int, Long>()
        var n = 0L
        var lastT = Long.MIN_VALUE
        NativeLogReader(dir.path).use { r ->
            val b = SampleBatch()
            while (r.read(b, 1000)) {
                for (i in 0 until b.size) {
                    kinds.merge(b.kind(i), 1L, Long::plus)
                    assertTrue(b.tNs(i) >= lastT || b.kind(i) == SampleKind.META, "time order at sample ${n + i}")
                    if (b.kind(i) != SampleKind.META) lastT = b.tNs(i)
                }
                n += b.size
            }
            assertEquals(0L, r.stats.skipped, "skipped rows")
            assertEquals(n, r.stats.samples)
        }
        assertEquals(dataRows(File(dir, "TotalAcceleration.csv")).toLong(), kinds[SampleKind.ACCEL])
        assertEquals(dataRows(File(dir, "Gyroscope.csv")).toLong(), kinds[SampleKind.GYRO])
        assertEquals(dataRows(File(dir, "Location.csv")).toLong(), kinds[SampleKind.FIX])
        assertEquals(dataRows(File(dir, "Barometer.csv")).toLong(), kinds[SampleKind.PRESSURE])
    }

    @Test
    fun aFileThatIsNoRecordingIsAnIOException() {
        val f = File(TestPaths.scratch("not-a-recording"), "notes.txt")
        f.writeText("shopping list\nmilk, bread\n")
        val e = assertFailsWith<IOException> { NativeLogReader(f.path) }
        assertTrue(e.message?.contains("expected a pdnav session log") == true, "message: ${e.message}")
        assertTrue(e.message?.contains("found first line 'shopping list'") == true, "message: ${e.message}")
    }
}
