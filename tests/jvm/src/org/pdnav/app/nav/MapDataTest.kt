package org.pdnav.app.nav

import org.junit.Test
import org.pdnav.app.map.MapData
import java.io.File
import kotlin.math.abs
import kotlin.math.cos
import kotlin.test.assertEquals
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/** The map's walkway graph and DEM bounds, read through the core's readers over JNI. */
class MapDataTest {
    private val root = File(System.getProperty("pdnav.root") ?: error("pdnav.root not set"))

    @Test
    fun graphEdgesAndDemBoundsComeOutInDegrees() {
        val graph = File(root, "tests/fuzz-corpus/graph_reader/small_l.graph")
        val dem = File(root, "tests/fuzz-corpus/dem_reader/andorra_4x4.pdem")
        val data = MapData.load(graph.path, dem.path)
        assertNull(data.error)
        // small_l.graph: origin 42.5 1.5; edge 0: (0,0) -> shape (50,0) -> (100,0); edge 1: (100,0) -> (100,30), (110,60) -> (110,100)
        assertEquals(listOf(3, 4), data.graphLines.map { it.size })
        val first = data.graphLines[0]
        assertEquals(42.5, first[0][0], 1e-9)
        assertEquals(1.5, first[0][1], 1e-9)
        val eastM = Math.toRadians(first[2][1] - 1.5) * 6_378_137.0 * cos(Math.toRadians(42.5))
        assertTrue(abs(eastM - 100.0) < 0.5, "100 m east came out as $eastM m")
        val last = data.graphLines[1].last()
        val northM = Math.toRadians(last[0] - 42.5) * 6_367_000.0
        assertTrue(abs(northM - 100.0) < 1.0, "100 m north came out as $northM m")
        // andorra_4x4.pdem: 5 x 5 nodes, 30 m cells, from -60 m to +60 m around 42.55, 1.55
        val b = assertNotNull(data.demBounds)
        assertEquals(42.55, b.centerLatDeg, 1e-6)
        assertEquals(1.55, b.centerLonDeg, 1e-6)
        assertTrue(abs((b.maxLatDeg - b.minLatDeg) * 111_000.0 - 120.0) < 2.0, "north-south extent")
    }

    @Test
    fun aBadGraphFileIsReportedNotThrown() {
        val bad = File(TestPaths.scratch("mapdata"), "bad.graph").apply { writeText("pdnav-graph 1\norigin 42.5\n") }
        val data = MapData.load(bad.path, "")
        assertTrue(data.graphLines.isEmpty())
        assertTrue(data.error?.contains("bad.graph") == true, "error names the file: ${data.error}")
    }
}
