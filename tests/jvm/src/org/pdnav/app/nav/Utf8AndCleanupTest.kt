package org.pdnav.app.nav

import org.junit.Test
import java.io.File
import java.io.IOException
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertTrue
import kotlin.test.fail

/**
 * Strings cross the bridge as real UTF-8 (through UTF-16), not JNI's Modified UTF-8: a file
 * name with an emoji opens that very path, an emoji in a Meta value is written as 4-byte
 * UTF-8 and read back intact, an error message naming such a path arrives intact; a native
 * handle that is never closed is released by the safety net.
 */
class Utf8AndCleanupTest {
    private val emoji = "\uD83D\uDEB6"  // U+1F6B6 PEDESTRIAN: a supplementary character (surrogate pair)

    @Test
    fun aPathAndAMetaValueWithAnEmojiSurviveTheBridge() {
        check(System.getProperty("sun.jnu.encoding").equals("UTF-8", ignoreCase = true)) {
            "the JVM must name files in UTF-8 (surefire sets LC_ALL=C.UTF-8), got ${System.getProperty("sun.jnu.encoding")}"
        }
        // a fresh folder per run: a broken bridge leaves a file whose name is not valid UTF-8,
        // which the next run could not delete
        val dir = TestPaths.scratch("utf8-${System.nanoTime()}")
        val file = File(dir, "séance_$emoji 日本.txt")
        val value = "Wanderung $emoji über den Pass"
        NativeRecorder(file.path, "Pixel $emoji").use { r ->
            r.write(SampleBatch().apply {
                addMeta(1_000_000_000L, "Note", value)
                addVector(SampleKind.ACCEL, 1_000_000_001L, 0.1, 0.2, 9.8)
            })
        }
        assertTrue(file.isFile, "the recorder created the path Kotlin named (dir holds ${dir.list()?.toList()})")
        assertEquals(1, dir.list()?.size, "and no other file")
        val bytes = file.readBytes()
        val utf8 = value.toByteArray(Charsets.UTF_8)
        assertTrue(indexOf(bytes, utf8) >= 0, "the Meta value is standard UTF-8 in the file (4-byte emoji, not CESU-8 surrogates)")
        var read = ""
        NativeLogReader(file.path).use { r ->
            val b = SampleBatch()
            while (r.read(b, 16)) for (i in 0 until b.size) if (b.kind(i) == SampleKind.META && b.string(i, 0) == "Note") read = b.string(i, 1)
        }
        assertEquals(value, read)

        val missing = File(dir, "fehlt_$emoji.txt").path
        val e = assertFailsWith<IOException> { NativeLogReader(missing) }
        assertTrue(e.message?.contains("fehlt_$emoji") == true, "error message keeps the path: ${e.message}")
        dir.deleteRecursively()
    }

    @Test
    fun aHandleNeverClosedIsReleasedByTheCleaner() {
        val file = File(TestPaths.scratch("cleaner"), "leaked.txt")
        val before = NativeCleaner.released
        leak(file)
        val deadline = System.nanoTime() + 20_000_000_000L
        while (NativeCleaner.released == before && System.nanoTime() < deadline) {
            System.gc()
            Thread.sleep(50)
        }
        if (NativeCleaner.released == before) fail("the dropped recorder was not released within 20 s")
        Thread.sleep(200)  // the release (close: hand lines to the OS) runs on the cleaner thread
        assertTrue(file.readText().contains("Accel"), "closing by the cleaner handed the buffered line to the OS")
    }

    private fun leak(file: File) {
        val r = NativeRecorder(file.path, flushIntervalNs = 1_000_000_000_000L)
        r.write(SampleBatch().apply { addVector(SampleKind.ACCEL, 1L, 0.1, 0.2, 9.8) })
        // no close(): r becomes unreachable here
    }

    private fun indexOf(hay: ByteArray, needle: ByteArray): Int {
        outer@ for (i in 0..hay.size - needle.size) {
            for (j in needle.indices) if (hay[i + j] != needle[j]) continue@outer
            return i
        }
        return -1
    }
}
