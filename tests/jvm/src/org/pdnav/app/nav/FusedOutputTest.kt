package org.pdnav.app.nav

import org.junit.Test
import kotlin.test.assertEquals
import kotlin.test.assertTrue

/**
 * Issue 14: the app's NativeNavigator (default mode "auto") returns the fused estimate and the
 * fused estimate's mode changes with their reasons. The real Mountain View log with a 60 s gap
 * cut into its Raw and Fix rows: the outage and the return must both be in the mode log.
 */
class FusedOutputTest {
    @Test
    fun nativeNavigatorReturnsTheFusedEstimateAndTheModeChangeReasons() {
        val log = TestPaths.sharedData("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt")
        val nav = TestPaths.sharedData("gnss-mountainview/hour2350.16n")
        val config = NavigatorConfig(navPaths = listOf(nav.path))
        NativeNavigator(config, 7).use { n ->
            NativeLogReader(log.path).use { reader ->
                val batch = SampleBatch(512)
                val kept = SampleBatch(512)
                var firstRaw = -1L
                while (reader.read(batch, 512)) {
                    kept.clear()
                    for (i in 0 until batch.size) {
                        val t = batch.tNs(i)
                        if ((batch.kind(i) == SampleKind.GNSS_RAW) && firstRaw < 0) firstRaw = t
                        val inGap = firstRaw >= 0 && t >= firstRaw + 90_000_000_000L && t < firstRaw + 150_000_000_000L
                        if (inGap && ((batch.kind(i) == SampleKind.GNSS_RAW) || (batch.kind(i) == SampleKind.FIX))) continue
                        kept.addCopy(batch, i)
                    }
                    n.feed(kept)
                }
            }
            val out = n.output(0)
            assertTrue(out.estimate.valid, "no fused estimate: ${out.estimate.reason}")
            assertTrue(out.estimate.reason.startsWith("fused (gnss)"), "not the fused estimate: ${out.estimate.reason}")
            assertEquals(EngineKind.GNSS, out.estimate.engine)
            val changes = n.modeChanges()
            assertTrue(changes.any { it.to == "pdr" && it.reason.contains("no usable GNSS") }, "outage not logged: $changes")
            assertTrue(changes.any { it.to == "gnss" && it.reason.contains("re-acquired") }, "return not logged: $changes")
            assertTrue(changes.zipWithNext().all { (a, b) -> a.to == b.from }, "mode log is not a chain: $changes")
        }
    }
}
