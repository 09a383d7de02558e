package org.pdnav.app.nav

import org.junit.Test
import java.io.File
import java.util.concurrent.TimeUnit
import kotlin.math.PI
import kotlin.math.abs
import kotlin.math.cos
import kotlin.math.sin
import kotlin.test.assertEquals
import kotlin.test.assertFailsWith
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * Issue 29 natives: NativeRouter (route::Router) answers as `pdnav route` does on the same
 * graph; navTakeSteps gives one estimate per step of a replayed log (as many as `pdnav replay`
 * counts); navFinish releases a walk shorter than the bout gate; geoInverse is the WGS84 geodesic.
 */
class RouteAndStepsBridgeTest {
    private val root = File(System.getProperty("pdnav.root") ?: error("pdnav.root not set"))

    private fun run(dir: File, vararg cmd: String): String {
        val out = File(dir, "cmd-${System.nanoTime()}.txt")
        val p = ProcessBuilder(*cmd).redirectErrorStream(true).redirectOutput(out).start()
        assertTrue(p.waitFor(300, TimeUnit.SECONDS), "timed out: ${cmd.joinToString(" ")}")
        val text = out.readText()
        assertTrue(p.exitValue() == 0 || p.exitValue() == 3, "failed (${p.exitValue()}): ${cmd.joinToString(" ")}\n$text")
        return text
    }

    /** The real Andorra walkway graph, built by dem-tools from the shared extract. */
    private fun andorraGraph(dir: File): File {
        val g = File(dir, "andorra.graph")
        run(dir, "/usr/bin/python3", File(root, "dem-tools/pdnav_graph.py").path,
            TestPaths.sharedData("terrain-andorra/andorra.osm.pbf").path, g.path)
        return g
    }

    private fun numberAfter(json: String, key: String): Double =
        Regex("\"$key\":(-?[0-9.eE+-]+)").find(json)?.groupValues?.get(1)?.toDouble()
            ?: error("no $key in $json")

    @Test
    fun routerEqualsTheCliOnTheAndorraGraph() {
        val dir = TestPaths.scratch("route-bridge")
        val graph = andorraGraph(dir)
        // Andorra la Vella -> Escaldes, a point near La Massana, an identical pair, one far off the map
        val queries = listOf(
            doubleArrayOf(42.5063, 1.5218, 42.5440, 1.5160),
            doubleArrayOf(42.5100, 1.5300, 42.5080, 1.5400),
            doubleArrayOf(42.5450, 1.5140, 42.5063, 1.5218),
            doubleArrayOf(42.5063, 1.5218, 42.5063, 1.5218),
            doubleArrayOf(40.0, 1.5218, 42.5063, 1.5218),
        )
        var paths = 0
        NativeRouter(graph.path).use { router ->
            for (q in queries) {
                val cli = run(dir, TestPaths.cli().path, "route", "--graph", graph.path,
                    "--from", "${q[0]},${q[1]}", "--to", "${q[2]},${q[3]}", "--json")
                val r = router.shortest(q[0], q[1], q[2], q[3])
                if (cli.contains("\"found\":false")) {
                    assertNull(r, "CLI found no path for ${q.toList()}, the bridge did: $r")
                    continue
                }
                assertNotNull(r, "CLI found a path for ${q.toList()}, the bridge none")
                paths++
                assertEquals(numberAfter(cli, "length_m"), r.lengthM, 1e-6, "length of ${q.toList()}")
                assertEquals(numberAfter(cli, "from_snap_m"), r.fromSnapM, 1e-6)
                assertEquals(numberAfter(cli, "to_snap_m"), r.toSnapM, 1e-6)
                // the polyline's along-track length is the reported length (local flat-earth metres)
                var sum = 0.0
                for (k in 1 until r.points.size) {
                    sum += NativeRouter.geoInverse(r.points[k - 1].first, r.points[k - 1].second,
                        r.points[k].first, r.points[k].second).first
                }
                assertEquals(r.lengthM, sum, 1e-3 * r.lengthM + 0.05, "polyline length of ${q.toList()}")
                assertTrue(r.points.size >= 2)
            }
        }
        assertEquals(4, paths, "paths among the queries")
    }

    @Test
    fun routerRejectsBadInputAndClosedHandles() {
        val graph = File(root, "tests/fuzz-corpus/graph_reader/small_l.graph")
        val router = NativeRouter(graph.path)
        assertFailsWith<IllegalArgumentException> { router.shortest(Double.NaN, 1.5, 42.5, 1.5) }
        assertFailsWith<IllegalArgumentException> { router.shortest(42.5, Double.POSITIVE_INFINITY, 42.5, 1.5) }
        val r = router.shortest(42.5, 1.5, 42.5, 1.5)
        assertNotNull(r)
        assertEquals(0.0, r.lengthM, 1e-9)
        router.close()
        router.close()  // idempotent
        assertFailsWith<IllegalStateException> { router.shortest(42.5, 1.5, 42.5, 1.5) }
        val bad = File(TestPaths.scratch("route-bad"), "bad.graph").apply { writeText("pdnav-graph 1\norigin 42.5\n") }
        val e = assertFailsWith<RuntimeException> { NativeRouter(bad.path) }
        assertTrue(e.message?.contains("bad.graph") == true, "error names the file: ${e.message}")
        assertFailsWith<IllegalArgumentException> { NativeBridge.routeOpen(null) }
    }

    @Test
    fun nullAndClosedHandlesThrowIllegalState() {
        assertFailsWith<IllegalStateException> { NativeBridge.navTakeSteps(0L) }
        assertFailsWith<IllegalStateException> { NativeBridge.navFinish(0L) }
        assertFailsWith<IllegalStateException> { NativeBridge.routeShortest(0L, 42.5, 1.5, 42.5, 1.5) }
        assertFailsWith<IllegalStateException> { NativeBridge.routeClose(0L) }
        val nav = NativeNavigator(NavigatorConfig(), 1L)
        nav.close()
        assertFailsWith<IllegalStateException> { nav.takeSteps() }
        assertFailsWith<IllegalStateException> { nav.finish() }
    }

    @Test
    fun geoInverseIsTheWgs84Geodesic() {
        // one degree of latitude at the equator: 110574.389 m (WGS84), bearing north
        val (d, b) = NativeRouter.geoInverse(0.0, 10.0, 1.0, 10.0)
        assertEquals(110574.389, d, 0.01)
        assertEquals(0.0, b, 1e-12)
        // due east along the equator: 1 deg = 111319.491 m, bearing pi/2
        val (d2, b2) = NativeRouter.geoInverse(0.0, 0.0, 0.0, 1.0)
        assertEquals(111319.491, d2, 0.01)
        assertEquals(PI / 2, b2, 1e-12)
        // south-west is in [0, 2pi)
        val (_, b3) = NativeRouter.geoInverse(42.5, 1.5, 42.49, 1.49)
        assertTrue(b3 > PI && b3 < 1.5 * PI, "bearing $b3")
        assertFailsWith<IllegalArgumentException> { NativeBridge.geoInverse(Double.NaN, 0.0, 0.0, 0.0) }
        assertFailsWith<IllegalArgumentException> { NativeBridge.geoInverse(91.0, 0.0, 0.0, 0.0) }
    }

    /** A walk simulated by the host CLI on an Andorra DEM tile (Android step events, barometer). */
    private fun simulatedWalk(dir: File): File {
        val dem = File(dir, "walk.pdem")
        val log = File(dir, "walk.log")
        run(dir, "/usr/bin/python3", File(root, "dem-tools/pdnav_dem.py").path, "tile",
            TestPaths.sharedData("terrain-andorra/N42E001.hgt.zip").path, "-o", dem.path,
            "--center", "42.5", "1.6", "--radius", "900", "--cell", "30", "--fill-voids")
        run(dir, TestPaths.cli().path, "simulate", "--dem", dem.path, "-o", log.path, "--seed", "7",
            "--min-length", "300", "--max-length", "500")
        return log
    }

    @Test
    fun oneEstimatePerStepOfAReplayedLog() {
        val dir = TestPaths.scratch("steps-bridge")
        val log = simulatedWalk(dir)
        val out = File(dir, "replay")
        run(dir, TestPaths.cli().path, "replay", log.path, "--out", out.path, "--quiet", "--engine", "dr")
        val summary = File(out, "summary.json").readText()
        val pdr = summary.substring(summary.indexOf("\"pdr\""))
        val cliSteps = Regex("\"steps\":\\s*([0-9]+)").find(pdr)!!.groupValues[1].toInt()
        val cliDistance = Regex("\"distance_m\":\\s*([0-9.eE+-]+)").find(pdr)!!.groupValues[1].toDouble()
        val trackTimes = File(out, "track.csv").readLines().drop(1).filter { it.isNotBlank() }
            .map { it.substringBefore(',').toLong() }.toSet()
        assertTrue(cliSteps > 100, "the simulated walk has steps: $cliSteps")

        val steps = mutableListOf<StepEstimate>()
        NativeNavigator(NavigatorConfig(mode = "dr", userHeightM = Double.NaN), 1L).use { nav ->
            NativeLogReader(log.path).use { reader ->
                val batch = SampleBatch(256)
                while (reader.read(batch, 256)) {
                    nav.feed(batch)
                    steps += nav.takeSteps()
                }
            }
            nav.finish()
            steps += nav.takeSteps()
            assertTrue(nav.takeSteps().isEmpty(), "taken steps are not returned twice")
        }
        assertEquals(cliSteps, steps.size, "per-step estimates vs pdnav replay's step count")
        for ((k, s) in steps.withIndex()) {
            assertTrue(s.hasPosition, "step $k has a position (start declared in the log)")
            assertTrue(s.tNs in trackTimes, "step $k at ${s.tNs} is a row of pdnav replay's track")
            assertTrue(s.headingRad >= 0.0 && s.headingRad < 2 * PI, "heading of step $k: ${s.headingRad}")
            assertTrue(s.sigmaEastM > 0.0 && s.sigmaNorthM > 0.0 && abs(s.corrEn) <= 1.0, "covariance of step $k")
            if (k > 0) {
                assertTrue(s.tNs >= steps[k - 1].tNs, "time order at step $k")
                assertTrue(s.distanceM > steps[k - 1].distanceM, "distance grows at step $k")
            }
        }
        assertEquals(cliDistance, steps.last().distanceM, 1e-6 * cliDistance, "distance walked vs pdnav replay")
        // the position moves along the heading: the last step's displacement matches its heading
        val a = steps[steps.size - 2]
        val b = steps.last()
        val (dStep, bearing) = NativeRouter.geoInverse(a.latDeg, a.lonDeg, b.latDeg, b.lonDeg)
        val stepLength = b.distanceM - a.distanceM
        assertEquals(stepLength, dStep, 0.05 * stepLength + 0.01, "last step's displacement")
        assertTrue(abs(sin(bearing - b.headingRad)) < 0.1 && cos(bearing - b.headingRad) > 0, "bearing $bearing vs heading ${b.headingRad}")
    }

    @Test
    fun finishReleasesAShortWalk() {
        // 3 accelerometer steps (shorter than the bout gate of 4) and a log that ends 0.5 s later
        // (core test NavigatorPdrWiring.ShortWalkReportedAtFinish, here through the bridge)
        fun walk(finish: Boolean): List<StepEstimate> {
            val steps = mutableListOf<StepEstimate>()
            NativeNavigator(NavigatorConfig(mode = "dr", startLatDeg = 34.05, startLonDeg = -118.25), 1L).use { nav ->
                val batch = SampleBatch(16)
                var t = 1_000_000_000L
                val cadenceHz = 1.8
                val walkFrom = t + 2_000_000_000L
                val walkTo = walkFrom + (3 / cadenceHz * 1e9).toLong()
                val end = walkTo + 500_000_000L
                while (t < end) {
                    t += 10_000_000L
                    val ts = (t - walkFrom) * 1e-9
                    val bounce = if (t >= walkFrom && t < walkTo) 2.0 * sin(2.0 * PI * cadenceHz * ts) else 0.0
                    batch.clear()
                    batch.addVector(SampleKind.ACCEL, t, 0.0, 9.81 + bounce, 0.0)
                    nav.feed(batch)
                    steps += nav.takeSteps()
                }
                assertTrue(steps.isEmpty(), "no step before the end of input: ${steps.size}")
                if (finish) {
                    nav.finish()
                    steps += nav.takeSteps()
                }
            }
            return steps
        }
        assertEquals(0, walk(false).size)
        val released = walk(true)
        assertEquals(3, released.size, "finish() releases the 3-step walk")
        assertTrue(released.all { it.hasPosition && it.distanceM > 0.0 })
        assertTrue(released[2].distanceM > released[1].distanceM && released[1].distanceM > released[0].distanceM)
    }
}
