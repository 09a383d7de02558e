package org.pdnav.app.nav

import org.junit.Test
import java.io.File
import java.util.concurrent.TimeUnit
import kotlin.math.abs
import kotlin.math.max
import kotlin.test.assertEquals
import kotlin.test.assertTrue

/**
 * A real session log replayed through NativeNavigator (the class the app uses), fed with the
 * rows NativeLogReader produces, gives the same estimates as the C++ replay CLI
 * (`pdnav replay LOG --out DIR` -> DIR/track.csv) on the same log.
 */
class ReplayMatchesCliTest {
    /** One track.csv row (or its Kotlin twin). */
    data class Row(val tNs: Long, val engine: String, val status: String, val lat: Double, val lon: Double,
                   val h: Double, val covEe: Double, val covEn: Double, val covNn: Double)

    /** Same rule as the CLI's ReplayRecorder: after every sample, keep a valid estimate whose
     *  time or status changed. */
    private fun kotlinTrack(log: File, config: NavigatorConfig, seed: Long): List<Row> {
        val rows = mutableListOf<Row>()
        var lastT = Long.MIN_VALUE
        var lastStatus = -1
        NativeNavigator(config, seed).use { nav ->
            NativeLogReader(log.path).use { reader ->
                val batch = SampleBatch(512)
                val one = SampleBatch(1)
                while (reader.read(batch, 512)) {
                    for (i in 0 until batch.size) {
                        one.clear()
                        one.addCopy(batch, i)
                        nav.feed(one)
                        val e = nav.estimate()
                        if (!e.valid || (e.tNs == lastT && e.statusCode == lastStatus)) continue
                        lastT = e.tNs
                        lastStatus = e.statusCode
                        rows += Row(e.tNs, e.engine.name.lowercase().replace('_', '-'),
                            e.status.name.lowercase().replace('_', '-'), e.latDeg, e.lonDeg, e.heightM,
                            e.covEastEastM2, e.covEastNorthM2, e.covNorthNorthM2)
                    }
                }
            }
        }
        return rows
    }

    private fun cliTrack(log: File, args: List<String>, name: String): List<Row> {
        val out = TestPaths.scratch("replay-cli-$name")
        val cmd = listOf(TestPaths.cli().path, "replay", log.path, "--out", out.path, "--quiet") + args
        val p = ProcessBuilder(cmd).redirectErrorStream(true).redirectOutput(out.resolve("stdout.txt")).start()
        assertTrue(p.waitFor(120, TimeUnit.SECONDS), "pdnav replay timed out")
        assertEquals(0, p.exitValue(), "pdnav replay failed: ${out.resolve("stdout.txt").readText()}")
        val lines = out.resolve("track.csv").readLines()
        val head = lines.first().split(',')
        fun col(n: String) = head.indexOf(n).also { assertTrue(it >= 0, "track.csv lacks $n") }
        val c = listOf("t_ns", "engine", "status", "lat_deg", "lon_deg", "h_m", "cov_ee_m2", "cov_en_m2", "cov_nn_m2").map(::col)
        return lines.drop(1).filter { it.isNotBlank() }.map { l ->
            val f = l.split(',')
            Row(f[c[0]].toLong(), f[c[1]], f[c[2]], f[c[3]].toDouble(), f[c[4]].toDouble(), f[c[5]].toDouble(),
                f[c[6]].toDouble(), f[c[7]].toDouble(), f[c[8]].toDouble())
        }
    }

    /** track.csv prints 12 significant digits. */
    private fun close(a: Double, b: Double) = a == b || (a.isNaN() && b.isNaN()) || abs(a - b) <= 1e-10 * max(1.0, max(abs(a), abs(b)))

    private fun assertSameTrack(cli: List<Row>, kt: List<Row>) {
        assertTrue(cli.isNotEmpty(), "the CLI produced no estimate: nothing to compare")
        assertEquals(cli.size, kt.size, "number of estimates")
        for ((i, pair) in cli.zip(kt).withIndex()) {
            val (a, b) = pair
            assertEquals(a.tNs, b.tNs, "t_ns of estimate $i")
            assertEquals(a.engine, b.engine, "engine of estimate $i")
            assertEquals(a.status, b.status, "status of estimate $i")
            for ((what, x, y) in listOf(Triple("lat", a.lat, b.lat), Triple("lon", a.lon, b.lon), Triple("h", a.h, b.h),
                    Triple("cov_ee", a.covEe, b.covEe), Triple("cov_en", a.covEn, b.covEn), Triple("cov_nn", a.covNn, b.covNn))) {
                assertTrue(close(x, y), "$what of estimate $i at ${a.tNs}: CLI $x, Kotlin $y")
            }
        }
    }

    @Test
    fun pixel7GnssLoggerLogMatchesTheCli() {
        val log = TestPaths.sharedData("gnss-pixel7-format/gnsslogger_v3_pixel7.txt")
        assertSameTrack(cliTrack(log, listOf("--seed", "1"), "pixel7"), kotlinTrack(log, NavigatorConfig(), 1L))
    }

    @Test
    fun mountainViewRawGnssLogWithEphemerisMatchesTheCli() {
        val log = TestPaths.sharedData("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt")
        val nav = TestPaths.sharedData("gnss-mountainview/hour2350.16n")
        val cli = cliTrack(log, listOf("--seed", "3", "--nav", nav.path), "mountainview")
        assertSameTrack(cli, kotlinTrack(log, NavigatorConfig(navPaths = listOf(nav.path)), 3L))
    }

    /** A real walk with every motion sensor (the shared Sensor Logger walk, read from its folder):
     *  the app's navigator estimates the phone's placement as `pdnav replay` does (a declared
     *  chest mount in the bridge gave another track), so an app session replays to its own track. */
    @Test
    fun sensorLoggerWalkWithMotionSensorsMatchesTheCli() {
        val walk = TestPaths.sharedDir("walk-ethz-sensorlogger/2023-03-17_15-50-47")
        // the app's NavigatorConfig states the walker's height (1.75 m unless set): the CLI gets it too
        val cli = cliTrack(walk, listOf("--seed", "2", "--height", "1.75"), "ethz")
        assertTrue(cli.size > 500, "the walk's estimates: ${cli.size}")
        assertSameTrack(cli, kotlinTrack(walk, NavigatorConfig(), 2L))
    }

    @Test
    fun batchSizeDoesNotChangeTheResult() {
        val log = TestPaths.sharedData("gnss-mountainview/pseudoranges_log_2016_08_22_14_45_50.txt")
        val nav = TestPaths.sharedData("gnss-mountainview/hour2350.16n")
        val cfg = NavigatorConfig(navPaths = listOf(nav.path))
        val finals = listOf(1, 64, 4096).map { size ->
            NativeNavigator(cfg, 5L).use { n ->
                replayLog(log.path, n, size)
                n.estimate()
            }
        }
        assertTrue(finals.all { it == finals[0] }, "final estimates differ by batch size: $finals")
    }
}
