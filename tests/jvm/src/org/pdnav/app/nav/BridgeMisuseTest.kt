package org.pdnav.app.nav

import org.junit.Test
import java.io.IOException
import java.util.concurrent.CountDownLatch
import java.util.concurrent.Executors
import java.util.concurrent.TimeUnit
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertTrue

/** Misuse of the JNI bridge must raise Java exceptions, never crash the JVM. */
class BridgeMisuseTest {
    private fun batchOfSteps(n: Int, t0: Long = 1_000_000_000L) = SampleBatch(n).apply {
        for (i in 0 until n) addStep(t0 + i * 500_000_000L)
    }

    @Test
    fun layoutAndNamesAgreeWithTheLibrary() {
        NativeBridge.ensureLoaded()
        // Kotlin enums are in the C++ enum order; names are the core's to_string().
        assertEquals(EngineKind.values().map { it.name.lowercase().replace('_', '-') }, NativeBridge.engineNames().toList())
        assertEquals(EstimateStatus.values().map { it.name.lowercase().replace('_', '-') }, NativeBridge.statusNames().toList())
        assertEquals(
            listOf(SampleLayout.VERSION, SampleLayout.INTS, SampleLayout.DOUBLES, SampleLayout.STRINGS, SampleLayout.BYTES, SampleKind.COUNT),
            NativeBridge.layout().toList(),
        )
    }

    @Test
    fun closeTwiceIsHarmlessAndCallsAfterCloseThrow() {
        val nav = NativeNavigator(NavigatorConfig(), 1L)
        nav.feed(batchOfSteps(3))
        nav.close()
        nav.close()
        assertTrue(nav.isClosed)
        assertFailsWith<IllegalStateException> { nav.feed(batchOfSteps(1)) }
        assertFailsWith<IllegalStateException> { nav.estimate() }
        assertFailsWith<IllegalStateException> { nav.output() }
        assertFailsWith<IllegalStateException> { nav.ignored() }
        assertFailsWith<IllegalStateException> { nav.setStart(1.0, 1.0, 5.0, 0L) }

        val dir = TestPaths.scratch("close-twice")
        val rec = NativeRecorder(dir.resolve("a.txt").path)
        rec.close()
        rec.close()
        assertFailsWith<IllegalStateException> { rec.write(batchOfSteps(1)) }
        assertFailsWith<IllegalStateException> { rec.flush() }
        assertFailsWith<IllegalStateException> { rec.linesWritten }

        val reader = NativeLogReader(dir.resolve("a.txt").path)
        reader.close()
        reader.close()
        assertFailsWith<IllegalStateException> { reader.read(SampleBatch()) }
    }

    @Test
    fun nullHandleThrowsIllegalState() {
        assertFailsWith<IllegalStateException> { NativeBridge.navEstimate(0L) }
        assertFailsWith<IllegalStateException> { NativeBridge.navClose(0L) }
        assertFailsWith<IllegalStateException> { NativeBridge.recFlush(0L) }
        assertFailsWith<IllegalStateException> { NativeBridge.readerProgress(0L) }
    }

    @Test
    fun malformedArraysThrowIllegalArgument() {
        NativeNavigator(NavigatorConfig(), 1L).use { nav ->
            val h = handleOf(nav)
            val b = batchOfSteps(4)
            // wrong lengths: n larger than the arrays
            assertFailsWith<IllegalArgumentException> {
                NativeBridge.navFeed(h, 5, b.kinds.copyOf(4), b.tNs, b.ints, b.doubles, b.strings, b.bytes)
            }
            assertFailsWith<IllegalArgumentException> {
                NativeBridge.navFeed(h, 4, b.kinds, LongArray(3), b.ints, b.doubles, b.strings, b.bytes)
            }
            assertFailsWith<IllegalArgumentException> {
                NativeBridge.navFeed(h, 4, b.kinds, b.tNs, LongArray(4 * SampleLayout.INTS - 1), b.doubles, b.strings, b.bytes)
            }
            assertFailsWith<IllegalArgumentException> {
                NativeBridge.navFeed(h, 4, b.kinds, b.tNs, b.ints, b.doubles, arrayOfNulls(1), b.bytes)
            }
            // nulls
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 1, null, b.tNs, b.ints, b.doubles, b.strings, b.bytes) }
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 1, b.kinds, null, b.ints, b.doubles, b.strings, b.bytes) }
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 1, b.kinds, b.tNs, b.ints, null, b.strings, b.bytes) }
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 1, b.kinds, b.tNs, b.ints, b.doubles, null, b.bytes) }
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 1, b.kinds, b.tNs, b.ints, b.doubles, b.strings, null) }
            // negative count, unknown kind, oversized navigation data, int field out of range
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, -1, b.kinds, b.tNs, b.ints, b.doubles, b.strings, b.bytes) }
            val bad = b.kinds.copyOf().also { it[2] = 99 }
            assertFailsWith<IllegalArgumentException> { NativeBridge.navFeed(h, 4, bad, b.tNs, b.ints, b.doubles, b.strings, b.bytes) }
            val nav2 = SampleBatch().apply { addNavMessage(1L, 3, 0x0101, 1, 1, 1, ByteArray(40)) }
            nav2.setLong(0, SampleBatch.NAV_LENGTH, 1000L)
            assertFailsWith<IllegalArgumentException> { nav.feed(nav2) }
            nav2.setLong(0, SampleBatch.NAV_LENGTH, 40L)
            nav2.setLong(0, 0, Long.MAX_VALUE)  // svid is an int in the core
            assertFailsWith<IllegalArgumentException> { nav.feed(nav2) }
            assertFailsWith<IllegalArgumentException> { nav.output(-1) }
            // the navigator is still usable after rejected calls
            nav.feed(b)
            nav.estimate()
        }
    }

    @Test
    fun badConfigurationThrowsJavaExceptions() {
        assertFailsWith<IllegalArgumentException> { NativeNavigator(NavigatorConfig(mode = "warp"), 1L) }
        assertFailsWith<IllegalArgumentException> { NativeNavigator(NavigatorConfig(particles = 0), 1L) }
        assertFailsWith<IllegalArgumentException> {
            NativeBridge.navCreate(null, Double.NaN, Double.NaN, 5.0, 1.75, false, "", "", arrayOf(), 500, "srtm", 1L)
        }
        val e = assertFailsWith<Exception> { NativeNavigator(NavigatorConfig(demPath = "/nonexistent/dem.tile"), 1L) }
        assertTrue(e is IOException || e is RuntimeException, "got $e")
        assertTrue(e.message.orEmpty().contains("/nonexistent/dem.tile"), "message names the file: ${e.message}")
        assertFailsWith<IOException> { NativeRecorder("/nonexistent/dir/x.txt") }
        assertFailsWith<IOException> { NativeLogReader("/nonexistent/log.txt") }
    }

    @Test
    fun callsFromTwoThreadsAreSerialised() {
        val dir = TestPaths.scratch("two-threads")
        val path = dir.resolve("threads.txt").path
        val perThread = 400
        val rowsPerBatch = 25
        NativeRecorder(path).use { rec ->
            NativeNavigator(NavigatorConfig(), 7L).use { nav ->
                val pool = Executors.newFixedThreadPool(2)
                val start = CountDownLatch(1)
                val futures = (0 until 2).map { th ->
                    pool.submit {
                        start.await()
                        val b = SampleBatch(rowsPerBatch)
                        for (k in 0 until perThread) {
                            b.clear()
                            for (r in 0 until rowsPerBatch) {
                                val t = 1_000_000_000L + (k * rowsPerBatch + r) * 10_000_000L
                                // one sensor type per thread: each type stays in time order
                                b.addVector(kindOf(th), t, th.toDouble(), k.toDouble(), r.toDouble())
                            }
                            rec.write(b)
                            nav.feed(b)
                            nav.estimate()
                        }
                    }
                }
                start.countDown()
                futures.forEach { it.get(60, TimeUnit.SECONDS) }
                pool.shutdown()
                nav.output()
            }
        }
        // every batch arrived whole: all lines intact, none lost, none skipped, in order per type
        val rows = IntArray(2)
        NativeLogReader(path).use { r ->
            val b = SampleBatch()
            while (r.read(b, 1000)) {
                for (i in 0 until b.size) {
                    val th = if (b.kind(i) == kindOf(0)) 0 else 1
                    assertEquals(kindOf(th), b.kind(i))
                    assertEquals(th.toDouble(), b.double(i, 0))
                    val seq = rows[th]++
                    assertEquals((seq / rowsPerBatch).toDouble(), b.double(i, 1), "batch index of row $seq")
                    assertEquals((seq % rowsPerBatch).toDouble(), b.double(i, 2), "row index of row $seq")
                }
            }
            assertEquals(0L, r.stats.skipped, "skipped lines")
        }
        assertEquals(listOf(perThread * rowsPerBatch, perThread * rowsPerBatch), rows.toList())
    }

    private fun kindOf(thread: Int) = if (thread == 0) SampleKind.ACCEL else SampleKind.GYRO

    /** The raw handle inside a NativeNavigator (for raw-array misuse tests only). */
    private fun handleOf(nav: NativeNavigator): Long {
        val f = NativeNavigator::class.java.getDeclaredField("h")
        f.isAccessible = true
        return (f.get(nav) as NativeHandle).get()
    }
}
