package org.pdnav.app.robo

import android.Manifest
import android.app.NotificationManager
import android.app.Service
import android.hardware.Sensor
import android.hardware.SensorManager
import android.location.GnssClock
import android.location.GnssMeasurement
import android.location.GnssMeasurementsEvent
import android.location.GnssStatus
import android.location.Location
import android.location.LocationManager
import android.os.Looper
import android.os.PowerManager
import android.os.SystemClock
import org.junit.Before
import org.junit.Test
import org.junit.runner.RunWith
import org.pdnav.app.nav.NativeLogReader
import org.pdnav.app.nav.NavEstimate
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.nav.SampleSink
import org.pdnav.app.recording.ReplayTask
import org.pdnav.app.recording.SessionStore
import org.pdnav.app.sensors.NavigationService
import org.pdnav.app.sensors.NavigationSession
import org.pdnav.app.sensors.SessionStats
import org.robolectric.Robolectric
import org.robolectric.RobolectricTestRunner
import org.robolectric.RuntimeEnvironment
import org.robolectric.Shadows.shadowOf
import org.robolectric.annotation.LooperMode
import org.robolectric.shadows.SensorEventBuilder
import org.robolectric.shadows.ShadowPowerManager
import org.robolectric.shadows.ShadowSensor
import org.robolectric.shadows.ShadowSystemClock
import java.io.File
import java.io.IOException
import java.time.Duration
import kotlin.math.abs
import kotlin.test.assertEquals
import kotlin.test.assertFalse
import kotlin.test.assertNotNull
import kotlin.test.assertNull
import kotlin.test.assertTrue

/**
 * The foreground service with injected SensorEvents (ShadowSensorManager) and GNSS
 * measurements / status / fixes (ShadowLocationManager): one time-ordered stream reaches the
 * bridge and the recording, the wake lock spans the session, a failing sink ends it cleanly,
 * a declared start belongs to one session and is recorded, replay reproduces it.
 */
@RunWith(RobolectricTestRunner::class)
@LooperMode(LooperMode.Mode.PAUSED)
class ServiceRoboTest {
    private val app = RuntimeEnvironment.getApplication()
    private val types = listOf(Sensor.TYPE_ACCELEROMETER, Sensor.TYPE_GYROSCOPE, Sensor.TYPE_MAGNETIC_FIELD,
        Sensor.TYPE_ROTATION_VECTOR, Sensor.TYPE_PRESSURE, Sensor.TYPE_STEP_DETECTOR, Sensor.TYPE_GYROSCOPE_UNCALIBRATED,
        Sensor.TYPE_GAME_ROTATION_VECTOR)
    private lateinit var sm: SensorManager
    private lateinit var lm: LocationManager
    private lateinit var sensors: Map<Int, Sensor>

    @Before
    fun setUp() {
        shadowOf(app).grantPermissions(Manifest.permission.ACCESS_FINE_LOCATION, Manifest.permission.ACTIVITY_RECOGNITION)
        sm = app.getSystemService(SensorManager::class.java)
        sensors = types.associateWith { ShadowSensor.newInstance(it).also { s -> shadowOf(sm).addSensor(s) } }
        lm = app.getSystemService(LocationManager::class.java)
        shadowOf(lm).setProviderEnabled(LocationManager.GPS_PROVIDER, true)
        ShadowPowerManager.clearWakeLocks()
    }

    private fun gnssEvent(tNs: Long, svids: List<Int>): GnssMeasurementsEvent {
        val clock = GnssClock().apply {
            timeNanos = 1_000_000_000_000L + tNs
            fullBiasNanos = -1_300_000_000_000_000_000L
            elapsedRealtimeNanos = tNs
        }
        val ms = svids.map { sv ->
            GnssMeasurement().apply {
                svid = sv
                constellationType = 1
                state = 16431
                receivedSvTimeNanos = 123_456_789L + sv
                cn0DbHz = 30.0 + sv
                pseudorangeRateMetersPerSecond = -100.0 * sv
                codeType = "C"
            }
        }
        return GnssMeasurementsEvent.Builder().setClock(clock).setMeasurements(ms).build()
    }

    private fun send(type: Int, t: Long, values: FloatArray) = shadowOf(sm).sendSensorEventToListeners(
        SensorEventBuilder.newBuilder().setSensor(sensors.getValue(type)).setTimestamp(t).setValues(values).build())

    /** One second of 100 Hz motion data (streams overlapping in time) and two GNSS epochs. */
    private fun injectSecond(t0: Long, n: Int = 100) {
        for (k in 0 until n) send(Sensor.TYPE_ACCELEROMETER, t0 + k * 10_000_000L, floatArrayOf(0.1f * (k % 10), 0f, 9.81f))
        for (k in 0 until n) send(Sensor.TYPE_GYROSCOPE, t0 + k * 10_000_000L, floatArrayOf(0f, 0.01f * k, 0f))
        for (k in 0 until n step 2) send(Sensor.TYPE_MAGNETIC_FIELD, t0 + k * 10_000_000L, floatArrayOf(20f, -5f, -40f))
        for (k in 0 until n step 2) send(Sensor.TYPE_ROTATION_VECTOR, t0 + k * 10_000_000L, floatArrayOf(0f, 0f, 0.3826834f, 0.9238795f, 0.1f))
        for (k in 0 until n step 4) send(Sensor.TYPE_GAME_ROTATION_VECTOR, t0 + k * 10_000_000L, floatArrayOf(0f, 0f, 0.5f, 0.8660254f))
        for (k in 0 until n step 10) send(Sensor.TYPE_PRESSURE, t0 + k * 10_000_000L, floatArrayOf(1013.25f))
        for (k in 0 until n step 10) send(Sensor.TYPE_GYROSCOPE_UNCALIBRATED, t0 + k * 10_000_000L, floatArrayOf(0f, 0.01f, 0f, 0.001f, 0.002f, 0.003f))
        send(Sensor.TYPE_STEP_DETECTOR, t0 + 550_000_000L, floatArrayOf(1f))
        shadowOf(lm).simulateGnssMeasurementsEvent(gnssEvent(t0 + 250_000_000L, listOf(3, 7, 12)))
        shadowOf(lm).simulateGnssMeasurementsEvent(gnssEvent(t0 + 750_000_000L, listOf(3, 7)))
    }

    private fun wakeLock(): PowerManager.WakeLock? = ShadowPowerManager.getLatestWakeLock()

    private fun idleWorker(service: NavigationService) {
        service.workLooper?.let { shadowOf(it).idle() }
        shadowOf(Looper.getMainLooper()).idle()
    }

    /**
     * Like [idleWorker], but bounded: a worker thread that died (an Error escaping the session's
     * handler) or is stuck makes the test fail after [seconds] instead of hanging it.
     */
    private fun idleWorkerBounded(service: NavigationService, seconds: Long = 20) {
        service.workLooper?.let { l ->
            val done = java.util.concurrent.CountDownLatch(1)
            if (android.os.Handler(l).post { done.countDown() }) {
                assertTrue(done.await(seconds, java.util.concurrent.TimeUnit.SECONDS),
                    "worker thread did not come back within $seconds s (dead or stuck)")
            }
        }
        shadowOf(Looper.getMainLooper()).idle()
    }

    private fun stopAndJoin(service: NavigationService) {
        val looper = service.workLooper
        service.stopSession()
        looper?.thread?.join(10_000)
        assertTrue(looper == null || !looper.thread.isAlive, "worker thread ended")
        shadowOf(Looper.getMainLooper()).idle()
    }

    private fun readAll(file: File): List<Triple<Int, Long, SampleBatch>> {
        val rows = mutableListOf<Triple<Int, Long, SampleBatch>>()
        NativeLogReader(file.path).use { r ->
            while (true) {
                val b = SampleBatch()
                if (!r.read(b, 1000)) break
                for (i in 0 until b.size) rows += Triple(b.kind(i), b.tNs(i), SampleBatch(1).apply { addCopy(b, i) })
            }
            assertEquals(0L, r.stats.skipped, "no line of the recording skipped")
        }
        return rows
    }

    @Test
    fun sensorAndGnssEventsReachTheBridgeInTimeOrderAndTheRecordingReplays() {
        val controller = Robolectric.buildService(NavigationService::class.java).create()
        val service = controller.get()
        val session = assertNotNull(service.startSession(navigate = true, record = true), service.lastError)
        idleWorker(service)
        assertNull(session.error)
        assertTrue(session.navigating && session.recording)
        assertEquals(types.toSet(), session.sensorTypes.toSet(), "every sensor registered")
        assertNotNull(shadowOf(service).lastForegroundNotification, "runs as a foreground service")
        val registered = assertNotNull(session.gnssRegistered)
        assertTrue(registered.measurements && registered.fixes && registered.status, "GNSS callbacks registered: $registered")
        assertTrue(wakeLock()?.isHeld == true, "partial wake lock held while the session runs")

        val t0 = SystemClock.elapsedRealtimeNanos()
        injectSecond(t0)
        val status = GnssStatus.Builder().addSatellite(GnssStatus.CONSTELLATION_GPS, 7, 41f, 55f, 120f, true, true, true,
            true, 1.57542e9f, false, 0f).build()
        shadowOf(lm).simulateGnssStatus(status)
        // the compass loses its calibration, then regains it (onAccuracyChanged has no timestamp:
        // the row takes the callback's elapsed time)
        session.sensors.onAccuracyChanged(sensors.getValue(Sensor.TYPE_MAGNETIC_FIELD), SensorManager.SENSOR_STATUS_UNRELIABLE)
        assertEquals(SensorManager.SENSOR_STATUS_UNRELIABLE, session.stats().magAccuracy, "magnetometer accuracy on screen")
        session.sensors.onAccuracyChanged(sensors.getValue(Sensor.TYPE_MAGNETIC_FIELD), SensorManager.SENSOR_STATUS_ACCURACY_HIGH)
        shadowOf(lm).simulateLocation(Location(LocationManager.GPS_PROVIDER).apply {
            latitude = 37.4; longitude = -122.08; accuracy = 4f; time = 1_700_000_000_000L
            elapsedRealtimeNanos = t0 + 500_000_000L
        })
        idleWorker(service)

        ShadowSystemClock.advanceBy(Duration.ofSeconds(3))
        session.pump()
        val nav = assertNotNull(session.navigator)
        val ignored = nav.ignored()
        assertTrue(ignored.keys.none { it.contains("order") || it.contains("backward") }, "navigator saw out-of-order samples: $ignored")
        assertEquals(0L, session.merger.lateRows, "rows emitted out of time order")
        assertNull(service.lastOutput, "no output() built while nobody listens")
        val stats = session.stats()
        assertEquals(2L, stats.gnssEpochs)
        assertEquals(1, stats.satellites.size)
        assertEquals(100L, stats.sensorRows["accel"])
        val file = assertNotNull(session.recordFile)

        stopAndJoin(service)
        assertNull(service.session)
        assertFalse(wakeLock()?.isHeld == true, "wake lock released on stop")

        // The recording: every injected sample, one time-ordered stream, an end marker.
        val counts = mutableMapOf<Int, Int>()
        var lastT = Long.MIN_VALUE
        val svids = mutableListOf<Long>()
        val accuracies = mutableListOf<Long>()
        val rows = readAll(file)
        for ((kind, t, b) in rows) {
            if (kind != SampleKind.META) {
                assertTrue(t >= lastT, "row time $t < previous $lastT")
                lastT = t
            }
            counts.merge(kind, 1, Int::plus)
            if (kind == SampleKind.GNSS_RAW) {
                svids += b.long(0, 5)
                assertEquals(30.0 + b.long(0, 5), b.double(0, 6), "Cn0 of svid ${b.long(0, 5)}")
            }
            if (kind == SampleKind.SENSOR_ACCURACY) {
                assertEquals(Sensor.TYPE_MAGNETIC_FIELD.toLong(), b.long(0, 1))
                accuracies += b.long(0, 2)
            }
            if (kind == SampleKind.GAME_ROTATION_VECTOR) {
                assertEquals(0.5, b.double(0, 2), 1e-6); assertEquals(0.8660254, b.double(0, 3), 1e-6)
            }
            if (kind == SampleKind.GNSS_STATUS) {
                assertEquals(7L, b.long(0, 4)); assertEquals(1L, b.long(0, 5)); assertEquals(55.0, b.double(0, 3), 1e-4)
            }
        }
        assertEquals(100, counts[SampleKind.ACCEL]); assertEquals(100, counts[SampleKind.GYRO])
        assertEquals(50, counts[SampleKind.MAG]); assertEquals(50, counts[SampleKind.ROTATION_VECTOR])
        assertEquals(10, counts[SampleKind.PRESSURE]); assertEquals(1, counts[SampleKind.STEP_DETECTOR])
        assertEquals(10, counts[SampleKind.UNCAL_GYRO], "uncalibrated gyroscope recorded")
        assertEquals(25, counts[SampleKind.GAME_ROTATION_VECTOR], "game rotation vector recorded")
        assertEquals(listOf(0L, 3L), accuracies, "magnetometer accuracy changes recorded in order")
        assertEquals(1, counts[SampleKind.GNSS_STATUS], "Status line per satellite")
        assertEquals(listOf(3L, 7L, 12L, 3L, 7L), svids)
        assertEquals(1, counts[SampleKind.FIX])
        val meta = rows.filter { it.first == SampleKind.META }.associate { it.third.string(0, 0) to it.third.string(0, 1) }
        assertTrue("Device" in meta && "AndroidApi" in meta && "GnssFullTracking" in meta, "phone and GNSS capabilities recorded: $meta")
        assertEquals("stopped", meta[NavigationSession.KEY_END], "end marker")

        // ... and it replays in the app's replay task, in batches (not one JNI call per row).
        var done: NavOutput? = null
        var error: Exception? = null
        val task = ReplayTask(file.path, NavigatorConfig(), 1L, onProgress = { _, _ -> }, onDone = { o, e -> done = o; error = e })
        task.run()
        assertNull(error)
        assertNotNull(done)
        assertTrue(task.feedCalls in 1..5, "replay fed ${rows.size} rows in ${task.feedCalls} JNI calls")
        controller.destroy()
    }

    @Test
    fun aThrowingSinkEndsTheSessionCleanlyKeepsTheFileAndSaysWhy() {
        for (failure in listOf<Throwable>(IOException("write failed: No space left on device"), UnsatisfiedLinkError("libpdnav_jni.so not found"))) {
            ShadowPowerManager.clearWakeLocks()
            val controller = Robolectric.buildService(NavigationService::class.java).create()
            val service = controller.get()
            val errors = mutableListOf<String>()
            service.addListener(object : NavigationService.Listener {
                override fun onOutput(output: NavOutput, track: List<DoubleArray>) = Unit
                override fun onError(message: String) { errors += message }
            })
            var calls = 0
            service.testSinks = listOf(object : SampleSink {
                override fun write(batch: SampleBatch) {
                    calls++
                    when (failure) {
                        is IOException -> throw failure
                        is Error -> throw failure
                    }
                }
            })
            val session = assertNotNull(service.startSession(navigate = true, record = true))
            idleWorker(service)
            val file = assertNotNull(session.recordFile)
            assertTrue(wakeLock()?.isHeld == true)
            injectSecond(SystemClock.elapsedRealtimeNanos())
            ShadowSystemClock.advanceBy(Duration.ofSeconds(3))
            service.workLooper?.let { l -> android.os.Handler(l).post { session.pump() } }
            idleWorkerBounded(service)
            idleWorkerBounded(service)
            assertTrue(calls >= 1, "the sink was called")
            val why = assertNotNull(service.lastError, "error reported for $failure")
            assertTrue(why.contains(if (failure is IOException) "No space left" else "native library"), why)
            assertEquals(listOf(why), errors, "listener told once")
            assertNull(service.session, "session ended")
            assertFalse(wakeLock()?.isHeld == true, "wake lock released on error")
            val nm = app.getSystemService(NotificationManager::class.java)
            assertTrue(shadowOf(nm).allNotifications.any { n -> n.extras.getCharSequence("android.text")?.contains(why) == true },
                "error notification posted")
            assertTrue(file.isFile, "recording kept")
            val meta = readAll(file).filter { it.first == SampleKind.META }.map { it.third.string(0, 0) to it.third.string(0, 1) }
            assertTrue(meta.any { it.first == NavigationSession.KEY_END && it.second.startsWith("error") }, "end marker says error: $meta")
            controller.destroy()
        }
    }

    @Test
    fun theNotificationShowsDurationSizeAndCountsPerLineType() {
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        val byKind = LongArray(SampleKind.COUNT).also {
            it[SampleKind.ACCEL] = 9500; it[SampleKind.GNSS_RAW] = 340; it[SampleKind.SENSOR_ACCURACY] = 2
        }
        val stats = SessionStats(durationNs = 100_000_000_000L, recordingNs = 3_725_000_000_000L, navigating = true,
            recording = true, fileName = "s.txt", fileBytes = 1_234_567L, rowsByKind = byKind, sensorRows = emptyMap(),
            gnssEpochs = 34L, fixes = 30L, lateRows = 0L, lastLate = null, magAccuracy = 3, satellites = emptyList(),
            lastFix = null, locationEnabled = true, checkpoints = emptyList())
        val text = service.stateText(stats)
        for (part in listOf("REC 01:02:05", "1.2 MB", "9842 lines", "Accel 9500", "Raw 340", "SensorAccuracy 2")) {
            assertTrue(part in text, "notification text has \"$part\": $text")
        }
        val n = service.buildNotification(text)
        assertEquals(text, n.extras.getCharSequence(android.app.Notification.EXTRA_BIG_TEXT)?.toString(), "expanded text")
        assertNotNull(n.actions?.firstOrNull { it.title.toString() == app.getString(org.pdnav.app.R.string.action_stop) }, "Stop action")
        // not recording: the duration only, no counts
        val idle = service.stateText(stats.copy(recording = false, navigating = false))
        assertEquals("00:01:40", idle)
    }

    @Test
    fun theTrackKeepsBoundedMemoryTheStartAndTheRecentPart() {
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        val n = 3 * NavigationService.TRACK_MAX
        for (k in 0 until n) {
            val e = NavEstimate(k * 1_000_000_000L, 1, 1, "", 42.5 + k * 1e-6, 1.5, 1500.0, 0.0, 0.0, 4.0, 0.0, 4.0, 3.0)
            service.publish(NavOutput(e, arrayOf(e), k.toLong(), DoubleArray(0)))
        }
        val track = service.track
        assertTrue(track.size <= NavigationService.TRACK_MAX, "track holds ${track.size} points after $n outputs")
        assertTrue(track.size >= NavigationService.TRACK_MAX / 2, "track thinned to ${track.size} points")
        assertEquals(42.5, track.first()[0], 1e-12, "the start is kept")
        assertEquals(42.5 + (n - 1) * 1e-6, track.last()[0], 1e-12, "the newest point is kept")
        // the recent part stays dense: the last 100 outputs are all there, in order
        for (j in 1..100) assertEquals(42.5 + (n - j) * 1e-6, track[track.size - j][0], 1e-12, "recent point $j")
        for (i in 1 until track.size) assertTrue(track[i][0] > track[i - 1][0], "track in time order at $i")
    }

    @Test
    fun wakeLockIsReleasedInOnDestroyAndTheNotificationHasAStopAction() {
        val controller = Robolectric.buildService(NavigationService::class.java).create()
        val service = controller.get()
        assertNotNull(service.startSession(navigate = false, record = true))
        idleWorker(service)
        assertTrue(wakeLock()?.isHeld == true)
        val n = assertNotNull(shadowOf(service).lastForegroundNotification)
        val stop = assertNotNull(n.actions?.firstOrNull { it.title.toString() == app.getString(org.pdnav.app.R.string.action_stop) }, "Stop action")
        val saved = shadowOf(stop.actionIntent).savedIntent
        assertEquals(NavigationService.ACTION_STOP, saved.action)
        assertTrue(shadowOf(stop.actionIntent).isService)
        assertEquals(Service.START_STICKY, service.onStartCommand(null, 0, 1), "a killed session is restarted and found")
        controller.destroy()
        assertFalse(wakeLock()?.isHeld == true, "wake lock released in onDestroy")
    }

    @Test
    fun aDeclaredStartBelongsToOneSessionIsRecordedAndTheReplayReproducesIt() {
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        // session 1: a start declared before it (header) and one mid-walk, and a checkpoint
        val s1 = assertNotNull(service.startSession(navigate = true, record = true, declaredStart = doubleArrayOf(42.5, 1.5, 5.0)))
        idleWorker(service)
        val t0 = SystemClock.elapsedRealtimeNanos()
        injectSecond(t0)
        ShadowSystemClock.advanceBy(Duration.ofSeconds(2))
        idleWorker(service)
        assertTrue(service.declareStart(42.501, 1.501, 3.0))
        assertTrue(service.checkpoint(42.5011, 1.5011))
        idleWorker(service)
        injectSecond(SystemClock.elapsedRealtimeNanos())
        ShadowSystemClock.advanceBy(Duration.ofSeconds(3))
        s1.pump()
        s1.merger.flush(SystemClock.elapsedRealtimeNanos(), all = true)  // everything the file will hold
        val live = assertNotNull(s1.navigator).estimate()
        assertEquals(1, assertNotNull(s1.feeder).startsApplied, "mid-walk start applied live")
        val f1 = assertNotNull(s1.recordFile)
        stopAndJoin(service)

        val meta1 = readAll(f1).filter { it.first == SampleKind.META }.map { it.third.string(0, 0) to it.third.string(0, 1) }
        assertEquals(listOf("42.5", "42.501"), meta1.filter { it.first == "StartLatitudeDegrees" }.map { it.second }, "both starts in the log")
        assertTrue(readAll(f1).any { it.first == SampleKind.TRUTH }, "checkpoint written as a Truth line")

        // the replay applies the recorded mid-walk start at its time: same estimate as live
        var replayed: NavOutput? = null
        val task = ReplayTask(f1.path, org.pdnav.app.ui.AppSettings(app.getSharedPreferences(org.pdnav.app.ui.AppSettings.PREFS, 0)).navigatorConfig(),
            1L, onProgress = { _, _ -> }, onDone = { o, _ -> replayed = o })
        task.run()
        val r = assertNotNull(replayed).estimate
        assertTrue(live.latDeg.isFinite(), "live estimate has a position")
        assertEquals(live.latDeg, r.latDeg, 1e-9, "replay reproduces the live estimate (lat)")
        assertEquals(live.lonDeg, r.lonDeg, 1e-9, "replay reproduces the live estimate (lon)")
        assertTrue(Math.abs(r.latDeg - 42.501) < 1e-3, "replay restarted at the mid-walk start: ${r.latDeg}")
        assertEquals(1, task.checkpoints.size, "checkpoint scored in replay")
        val c = task.checkpoints[0]
        assertTrue(c.errorM.isFinite() && c.errorM < 50.0, "checkpoint error ${c.errorM} m")
        NativeLogReader(f1.path).use { } // file still readable

        // session 2 without a declared start: nothing carried over, neither in config nor log
        assertTrue(service.startSession(navigate = true, record = true) != null)
        idleWorker(service)
        val s2 = assertNotNull(service.session)
        val f2 = assertNotNull(s2.recordFile)
        stopAndJoin(service)
        val meta2 = readAll(f2).filter { it.first == SampleKind.META }.map { it.third.string(0, 0) }
        assertTrue("StartLatitudeDegrees" !in meta2, "session 2 must not inherit session 1's start: $meta2")
        assertTrue(org.pdnav.app.ui.AppSettings(app.getSharedPreferences(org.pdnav.app.ui.AppSettings.PREFS, 0)).navigatorConfig().startLatDeg.isNaN())
    }

    @Test
    fun aKilledSessionIsFoundMarkedAndOfferedForReplay() {
        val store = SessionStore(app)
        val f = store.newSessionFile(1_700_000_000_000L)
        f.writeText("# pdnav-log\nMeta,5000000000,Device,test\nAccel,,6000000000,0.1,0.2,9.8\nAccel,,7000000000,0.1,0.2,9")  // torn
        store.markActive(f)
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        assertEquals(f, service.interrupted)
        val meta = NativeLogReader(f.path).use { r ->
            val b = SampleBatch()
            val out = mutableListOf<Pair<String, String>>()
            while (r.read(b, 100)) for (i in 0 until b.size) if (b.kind(i) == SampleKind.META) out += b.string(i, 0) to b.string(i, 1)
            out
        }
        assertTrue(NavigationSession.KEY_END to "interrupted" in meta, "end marker appended: $meta")
        assertNull(SessionStore(app).recoverInterrupted(), "found once")
    }

    /**
     * Issue 29: Go-to chosen on the Places screen reaches the service through the map screen;
     * the in-app replay (owned by the service) opens on the installed region by itself and
     * publishes the walker's state with Go-to to the screen.
     */
    @Test
    fun goToFromThePlacesScreenReachesTheServiceAndTheReplayPublishesIt() {
        shadowOf(app).grantPermissions(android.Manifest.permission.ACCESS_FINE_LOCATION, android.Manifest.permission.ACCESS_COARSE_LOCATION,
            android.Manifest.permission.ACTIVITY_RECOGNITION)
        val pack = RegionFixture.build("Engolasters", "--center", "${BasemapFixture.CENTER_LAT},${BasemapFixture.CENTER_LON}",
            "--radius", "${BasemapFixture.RADIUS_M}")
        pack.inputStream().use { org.pdnav.app.region.RegionStore(app.filesDir).install(it, pack.name) }
        val (_, log) = BasemapFixture.simulatedWalk()
        val service = Robolectric.buildService(NavigationService::class.java).create().get()
        shadowOf(app).setComponentNameAndServiceForBindService(android.content.ComponentName(app, NavigationService::class.java),
            service.onBind(android.content.Intent(app, NavigationService::class.java)))
        val goTo = android.content.Intent(app, org.pdnav.app.ui.MainActivity::class.java)
            .putExtra(org.pdnav.app.ui.MainActivity.EXTRA_GOTO_NAME, "Hut")
            .putExtra(org.pdnav.app.ui.MainActivity.EXTRA_GOTO_LAT, 42.51881)
            .putExtra(org.pdnav.app.ui.MainActivity.EXTRA_GOTO_LON, 1.56896)
        val screen = Robolectric.buildActivity(org.pdnav.app.ui.MainActivity::class.java, goTo).setup()
        shadowOf(Looper.getMainLooper()).idle()
        assertEquals("Hut", service.goToTarget?.name, "the map screen handed Go-to to the service")
        val walks = ArrayList<org.pdnav.app.walk.WalkState>()
        service.addListener(object : NavigationService.Listener {
            override fun onOutput(output: NavOutput, track: List<DoubleArray>) = Unit
            override fun onWalk(state: org.pdnav.app.walk.WalkState) { walks += state }
        })
        // the state line: a hint while nothing runs and nothing is shown, then what happens
        val stateView = screen.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.status_text)
        val hints = listOf(app.getString(org.pdnav.app.R.string.status_idle), app.getString(org.pdnav.app.R.string.status_no_basemap))
        assertTrue(stateView.text.toString() in hints, "no session, no walk: a hint (${stateView.text})")
        assertTrue(service.startReplay(log.path))
        assertTrue(stateView.text.startsWith("Replaying ${log.name} ("), "while it runs: ${stateView.text}")
        val task = assertNotNull(service.replay)
        task.join(120_000)
        shadowOf(Looper.getMainLooper()).idle()
        assertEquals(app.getString(org.pdnav.app.R.string.status_replay_done, log.name), stateView.text.toString(),
            "the replayed walk is shown: its state, not the idle hint")
        assertEquals(android.view.View.VISIBLE, stateView.visibility)
        // the arrow on the map points where the heading text says (the latest step's heading)
        val headingText = screen.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.walker_heading).text.toString()
        val shownDeg = assertNotNull(Regex("\\((\\d+)°\\)").find(headingText), headingText).groupValues[1].toDouble()
        val markerDeg = screen.get().map.markerHeadingDeg
        assertTrue(abs(((markerDeg - shownDeg) % 360.0 + 540.0) % 360.0 - 180.0) <= 1.0,
            "the arrow is turned to $markerDeg°, the screen says \"$headingText\"")
        assertEquals("Engolasters", service.region?.name, "the replay opened on the region containing its start")
        val g = assertNotNull(service.lastWalk?.goTo, "Go-to published")
        assertEquals("Hut", g.place.name)
        assertNotNull(g.route, "a walkway route to the hut")
        // one report per 512-row batch: this sparse simulated log (~10 rows/s) gives one every ~50 s
        assertTrue(walks.mapNotNull { it.goTo }.map { it.straightM }.distinct().size >= 5, "updates as the walk goes: ${walks.size}")
        val text = screen.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.goto_text).text.toString()
        assertTrue(text.startsWith("Go to Hut: ") && text.contains("along paths"), "the screen shows it: $text")
        assertEquals("Map: Engolasters", screen.get().findViewById<android.widget.TextView>(org.pdnav.app.R.id.region_text).text.toString())
        screen.destroy()
    }
}
