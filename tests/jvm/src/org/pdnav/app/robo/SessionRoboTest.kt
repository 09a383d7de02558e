package org.pdnav.app.robo

import android.hardware.SensorManager
import android.location.LocationManager
import android.os.Handler
import android.os.Looper
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.sensors.NavigationSession
import org.pdnav.app.sensors.SampleMerger
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleSink
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.annotation.LooperMode
import java.io.File
import kotlin.test.assertEquals
import kotlin.test.assertTrue

/** NavigationSession on a controlled clock: fsync cadence, late rows reported. */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
class SessionRoboTest {
    private val app = RuntimeEnvironment.getApplication()

    @Test
    fun theRecordingIsSyncedEveryTenSecondsAndOnClose() {
        var now = 1_000_000_000L
        val synced = mutableListOf<Long>()
        val s = NavigationSession(
            handler = Handler(Looper.getMainLooper()),
            sensorManager = app.getSystemService(SensorManager::class.java),
            locationManager = app.getSystemService(LocationManager::class.java),
            config = NavigatorConfig(),
            clockNs = { now },
            events = object : NavigationSession.Events {},
            syncFile = { synced += now },
        )
        assertTrue(s.open())
        val file = File(app.filesDir, "sync-test.txt")
        assertTrue(s.startRecording(file, listOf("Device" to "test")))
        repeat(125) {  // 25 s in 200 ms pumps
            now += 200_000_000L
            s.pump()
        }
        assertEquals(listOf(11_000_000_000L, 21_000_000_000L), synced, "fsync every 10 s of recording")
        s.stopRecording()
        assertEquals(3, synced.size, "and on close")
        s.stop()
    }

    @Test
    fun aLateRowIsReportedWithItsKindAndDelay() {
        val reports = mutableListOf<String>()
        val out = mutableListOf<Long>()
        val m = SampleMerger(1_000L, listOf(object : SampleSink {
            override fun write(batch: SampleBatch) { for (i in 0 until batch.size) out += batch.tNs(i) }
        })) { kind, t, behind -> reports += "${NavigationSession.kindName(kind)}@$t-$behind" }
        m.add { it.addVector(SampleKind.ACCEL, 5_000L, 0.0, 0.0, 9.8) }
        m.flush(10_000L)
        m.add { it.addVector(SampleKind.GYRO, 3_000L, 0.0, 0.0, 0.0) }  // older than what was emitted
        m.flush(10_000L)
        assertEquals(listOf(5_000L, 3_000L), out, "the late row is still emitted")
        assertEquals(1L, m.lateRows)
        assertEquals(listOf("Gyro@3000-2000"), reports)
        assertEquals(1L, m.emittedByKind()[SampleKind.GYRO])
    }
}
