package org.pdnav.app.sensors

import android.hardware.Sensor
import android.hardware.SensorEvent
import android.hardware.SensorEventListener
import android.hardware.SensorManager
import android.os.Handler
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import kotlin.math.sqrt

/**
 * The phone's motion and pressure sensors, registered with explicit rates and hardware
 * batching, converted into [SampleBatch] rows on the merger. SensorEvent.timestamp is on the
 * elapsedRealtimeNanos clock on Android 7+ phones (the project's common timeline).
 */
class SensorSource(private val sensors: SensorManager, private val merger: SampleMerger) : SensorEventListener {

    /** One sensor subscription: type, sampling period and allowed report latency. */
    data class Rate(val type: Int, val periodUs: Int, val maxLatencyUs: Int)

    private val registered = mutableListOf<Sensor>()

    /** Registers every available sensor of [RATES]; returns the types registered. */
    fun start(handler: Handler?): List<Int> {
        val types = mutableListOf<Int>()
        for (r in RATES) {
            val s = sensors.getDefaultSensor(r.type) ?: continue
            if (sensors.registerListener(this, s, r.periodUs, r.maxLatencyUs, handler)) {
                registered += s
                types += r.type
            }
        }
        return types
    }

    fun stop() {
        sensors.unregisterListener(this)
        registered.clear()
    }

    override fun onSensorChanged(event: SensorEvent) {
        val t = event.timestamp
        val v = event.values
        merger.add { b -> addEvent(b, event.sensor.type, t, v) }
    }

    override fun onAccuracyChanged(sensor: Sensor, accuracy: Int) = Unit

    companion object {
        /** Batching: up to 100 ms of samples per delivery (saves power, keeps latency low). */
        private const val LATENCY_US = 100_000

        /** 100 Hz inertial (step detection needs >= 50 Hz), 50 Hz mag/rotation, 10 Hz baro. */
        val RATES = listOf(
            Rate(Sensor.TYPE_ACCELEROMETER, 10_000, LATENCY_US),
            Rate(Sensor.TYPE_GYROSCOPE, 10_000, LATENCY_US),
            Rate(Sensor.TYPE_MAGNETIC_FIELD, 20_000, LATENCY_US),
            Rate(Sensor.TYPE_ROTATION_VECTOR, 20_000, LATENCY_US),
            Rate(Sensor.TYPE_PRESSURE, 100_000, LATENCY_US),
            Rate(Sensor.TYPE_STEP_DETECTOR, 0, 0),
        )

        /** Appends one SensorEvent (type, timestamp, values) as a row; other types are ignored. */
        fun addEvent(b: SampleBatch, type: Int, t: Long, v: FloatArray) {
            when (type) {
                Sensor.TYPE_ACCELEROMETER -> if (v.size >= 3) b.addVector(SampleKind.ACCEL, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_GYROSCOPE -> if (v.size >= 3) b.addVector(SampleKind.GYRO, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_MAGNETIC_FIELD -> if (v.size >= 3) b.addVector(SampleKind.MAG, t, v[0].toDouble(), v[1].toDouble(), v[2].toDouble())
                Sensor.TYPE_PRESSURE -> if (v.isNotEmpty()) b.addPressure(t, v[0] * 100.0)  // hPa -> Pa
                Sensor.TYPE_ROTATION_VECTOR -> if (v.size >= 3) addRotation(b, t, v)
                Sensor.TYPE_STEP_DETECTOR -> b.addStep(t)
            }
        }

        private fun addRotation(b: SampleBatch, t: Long, v: FloatArray) {
            val x = v[0].toDouble()
            val y = v[1].toDouble()
            val z = v[2].toDouble()
            // values[3] (w) is optional on old devices: recover it from the unit norm.
            val w = if (v.size >= 4) v[3].toDouble() else sqrt((1.0 - x * x - y * y - z * z).coerceAtLeast(0.0))
            // values[4]: estimated heading accuracy (rad), -1 when unavailable.
            val acc = if (v.size >= 5 && v[4] >= 0f) v[4].toDouble() else Double.NaN
            b.addRotationVector(t, x, y, z, w, acc)
        }
    }
}
