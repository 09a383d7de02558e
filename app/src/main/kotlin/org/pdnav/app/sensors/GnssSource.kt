package org.pdnav.app.sensors

import android.location.GnssClock
import android.location.GnssMeasurement
import android.location.GnssMeasurementsEvent
import android.location.GnssNavigationMessage
import android.location.GnssStatus
import android.location.Location
import android.location.LocationListener
import android.location.LocationManager
import android.os.Build
import android.os.Bundle
import android.os.Handler
import android.os.SystemClock
import org.pdnav.app.nav.FixRow
import org.pdnav.app.nav.GnssRawRow
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleLayout.MISSING

/**
 * Raw GNSS measurements (with their clock), navigation messages (broadcast ephemeris bits)
 * and the phone's own fixes, as rows on the merger. A measurement epoch is time-stamped with
 * GnssClock.elapsedRealtimeNanos where the phone reports it (Android 10+), else with the
 * callback's arrival time; fixes with Location.elapsedRealtimeNanos.
 */
class GnssSource(
    private val locations: LocationManager,
    private val merger: SampleMerger,
    private val elapsedNs: () -> Long = { SystemClock.elapsedRealtimeNanos() },
    private val wallMs: () -> Long = { System.currentTimeMillis() },
    private val onEvent: () -> Unit = {},
) {
    /** What could be registered (a refused permission or a missing provider leaves it false). */
    data class Registered(val measurements: Boolean, val navigation: Boolean, val fixes: Boolean, val status: Boolean = false)

    /** One satellite of the latest GnssStatus (the satellite view and sky plot). */
    data class Satellite(
        val constellation: Int, val svid: Int, val cn0DbHz: Double, val elevationDeg: Double,
        val azimuthDeg: Double, val usedInFix: Boolean, val carrierHz: Double,
    )

    @Volatile var epochs = 0L
        private set
    @Volatile var fixes = 0L
        private set
    @Volatile var navMessages = 0L
        private set
    /** The phone's own latest GPS fix (lat, lon, accuracy m), or null. */
    @Volatile var lastFix: FixRow? = null
        private set
    @Volatile var satellites: List<Satellite> = emptyList()
        private set
    /** False once the user switched location off (the screen prompts to switch it on). */
    @Volatile var providerEnabled = true
        private set

    val measurementCallback = object : GnssMeasurementsEvent.Callback() {
        override fun onGnssMeasurementsReceived(event: GnssMeasurementsEvent) {
            val t = epochTimeNs(event.clock, elapsedNs())
            val utc = wallMs()
            val rows = event.measurements.map { toRow(event.clock, it, utc) }
            val agc = agcRows(event)
            merger.add { b ->
                rows.forEach { b.addGnssRaw(t, it) }
                agc.forEach { a -> b.addAgc(t, utc, event.clock.timeNanos, a.constellation, a.levelDb, a.carrierHz) }
            }
            epochs++
            onEvent()
        }
    }

    val navigationCallback = object : GnssNavigationMessage.Callback() {
        override fun onGnssNavigationMessageReceived(m: GnssNavigationMessage) {
            val t = elapsedNs()
            val data = m.data ?: ByteArray(0)
            if (data.size > org.pdnav.app.nav.SampleLayout.BYTES) return  // not a message the core decodes
            merger.add { b -> b.addNavMessage(t, m.svid, m.type, m.status, m.messageId, m.submessageId, data) }
            navMessages++
        }
    }

    /** GnssStatus -> `Status` lines (GnssLogger's columns) and the satellite view. */
    val statusCallback = object : GnssStatus.Callback() {
        override fun onSatelliteStatusChanged(status: GnssStatus) {
            val t = elapsedNs()
            val utc = wallMs()
            val n = status.satelliteCount
            val sats = (0 until n).map { i ->
                Satellite(status.getConstellationType(i), status.getSvid(i), status.getCn0DbHz(i).toDouble(),
                    status.getElevationDegrees(i).toDouble(), status.getAzimuthDegrees(i).toDouble(), status.usedInFix(i),
                    if (Build.VERSION.SDK_INT >= 26 && status.hasCarrierFrequencyHz(i)) status.getCarrierFrequencyHz(i).toDouble() else Double.NaN)
            }
            val almanac = BooleanArray(n) { status.hasAlmanacData(it) }
            val ephemeris = BooleanArray(n) { status.hasEphemerisData(it) }
            val baseband = DoubleArray(n) {
                if (Build.VERSION.SDK_INT >= 30 && status.hasBasebandCn0DbHz(it)) status.getBasebandCn0DbHz(it).toDouble() else Double.NaN
            }
            satellites = sats
            merger.add { b ->
                sats.forEachIndexed { i, s ->
                    b.addStatus(t, utc, n, i, s.constellation, s.svid, s.usedInFix, almanac[i], ephemeris[i], s.carrierHz,
                        s.cn0DbHz, s.azimuthDeg, s.elevationDeg, baseband[i])
                }
            }
            onEvent()
        }
    }

    val locationListener = object : LocationListener {
        override fun onLocationChanged(location: Location) {
            val row = toFix(location)
            merger.add { b -> b.addFix(location.elapsedRealtimeNanos, row) }
            if (row.provider == "GPS") lastFix = row
            fixes++
            providerEnabled = true
            onEvent()
        }
        @Suppress("OVERRIDE_DEPRECATION")  // abstract before API 30: must stay implemented
        override fun onStatusChanged(provider: String?, status: Int, extras: Bundle?) = Unit
        override fun onProviderEnabled(provider: String) { providerEnabled = true }
        override fun onProviderDisabled(provider: String) { providerEnabled = false }
    }

    private data class Agc(val constellation: Int, val levelDb: Double, val carrierHz: Double)

    private fun agcRows(event: GnssMeasurementsEvent): List<Agc> {
        if (Build.VERSION.SDK_INT < 33) return emptyList()
        return event.gnssAutomaticGainControls.map { Agc(it.constellationType, it.levelDb, it.carrierFrequencyHz.toDouble()) }
    }

    /**
     * Registers the callbacks on [handler]'s thread. Needs ACCESS_FINE_LOCATION.
     * [fullTracking] (API 31+) asks the chipset for measurements without duty cycling
     * (GnssMeasurementRequest.setFullTracking; costs battery, gives continuous carrier phase).
     */
    @Suppress("DEPRECATION")
    fun start(handler: Handler, fullTracking: Boolean = false): Registered {
        providerEnabled = try {
            locations.isProviderEnabled(LocationManager.GPS_PROVIDER)
        } catch (e: RuntimeException) {
            false
        }
        val meas = guard {
            if (fullTracking && Build.VERSION.SDK_INT >= 31) {
                val request = android.location.GnssMeasurementRequest.Builder().setFullTracking(true).build()
                locations.registerGnssMeasurementsCallback(request, { r: Runnable -> handler.post(r) }, measurementCallback)
            } else {
                locations.registerGnssMeasurementsCallback(measurementCallback, handler)
            }
        }
        val nav = guard { locations.registerGnssNavigationMessageCallback(navigationCallback, handler) }
        val status = guard { locations.registerGnssStatusCallback(statusCallback, handler) }
        val fix = guard {
            locations.requestLocationUpdates(LocationManager.GPS_PROVIDER, 1000L, 0f, locationListener, handler.looper)
            true
        }
        return Registered(meas, nav, fix, status)
    }

    fun stop() {
        locations.unregisterGnssMeasurementsCallback(measurementCallback)
        locations.unregisterGnssNavigationMessageCallback(navigationCallback)
        locations.unregisterGnssStatusCallback(statusCallback)
        locations.removeUpdates(locationListener)
    }

    private fun guard(register: () -> Boolean): Boolean = try {
        register()
    } catch (e: SecurityException) {
        false
    } catch (e: IllegalArgumentException) {
        false  // provider absent (e.g. no GPS on an emulator image)
    }

    companion object {
        fun epochTimeNs(clock: GnssClock, arrivalNs: Long): Long =
            if (Build.VERSION.SDK_INT >= 29 && clock.hasElapsedRealtimeNanos()) clock.elapsedRealtimeNanos else arrivalNs

        @Suppress("DEPRECATION")
        fun toRow(c: GnssClock, m: GnssMeasurement, utcMs: Long): GnssRawRow {
            val sdk = Build.VERSION.SDK_INT
            return GnssRawRow(
                utcMs = utcMs,
                timeNanos = c.timeNanos,
                leapSecond = if (c.hasLeapSecond()) c.leapSecond.toLong() else MISSING,
                fullBiasNanos = if (c.hasFullBiasNanos()) c.fullBiasNanos else MISSING,
                hardwareClockDiscontinuityCount = c.hardwareClockDiscontinuityCount.toLong(),
                svid = m.svid.toLong(),
                state = m.state.toLong(),
                receivedSvTimeNanos = m.receivedSvTimeNanos,
                receivedSvTimeUncertaintyNanos = m.receivedSvTimeUncertaintyNanos,
                accumulatedDeltaRangeState = m.accumulatedDeltaRangeState.toLong(),
                carrierCycles = if (m.hasCarrierCycles()) m.carrierCycles else MISSING,
                multipathIndicator = m.multipathIndicator.toLong(),
                constellationType = m.constellationType.toLong(),
                chipsetElapsedRealtimeNanos = if (sdk >= 29 && c.hasElapsedRealtimeNanos()) c.elapsedRealtimeNanos else MISSING,
                timeUncertaintyNanos = if (c.hasTimeUncertaintyNanos()) c.timeUncertaintyNanos else Double.NaN,
                biasNanos = if (c.hasBiasNanos()) c.biasNanos else Double.NaN,
                biasUncertaintyNanos = if (c.hasBiasUncertaintyNanos()) c.biasUncertaintyNanos else Double.NaN,
                driftNanosPerSecond = if (c.hasDriftNanosPerSecond()) c.driftNanosPerSecond else Double.NaN,
                driftUncertaintyNanosPerSecond = if (c.hasDriftUncertaintyNanosPerSecond()) c.driftUncertaintyNanosPerSecond else Double.NaN,
                timeOffsetNanos = m.timeOffsetNanos,
                cn0DbHz = m.cn0DbHz,
                pseudorangeRateMps = m.pseudorangeRateMetersPerSecond,
                pseudorangeRateUncertaintyMps = m.pseudorangeRateUncertaintyMetersPerSecond,
                accumulatedDeltaRangeM = m.accumulatedDeltaRangeMeters,
                accumulatedDeltaRangeUncertaintyM = m.accumulatedDeltaRangeUncertaintyMeters,
                carrierFrequencyHz = if (m.hasCarrierFrequencyHz()) m.carrierFrequencyHz.toDouble() else Double.NaN,
                carrierPhase = if (m.hasCarrierPhase()) m.carrierPhase else Double.NaN,
                carrierPhaseUncertainty = if (m.hasCarrierPhaseUncertainty()) m.carrierPhaseUncertainty else Double.NaN,
                snrDb = if (m.hasSnrInDb()) m.snrInDb else Double.NaN,
                agcDb = if (sdk >= 26 && m.hasAutomaticGainControlLevelDb()) m.automaticGainControlLevelDb else Double.NaN,
                basebandCn0DbHz = if (sdk >= 30 && m.hasBasebandCn0DbHz()) m.basebandCn0DbHz else Double.NaN,
                fullInterSignalBiasNanos = if (sdk >= 30 && m.hasFullInterSignalBiasNanos()) m.fullInterSignalBiasNanos else Double.NaN,
                fullInterSignalBiasUncertaintyNanos = if (sdk >= 30 && m.hasFullInterSignalBiasUncertaintyNanos()) m.fullInterSignalBiasUncertaintyNanos else Double.NaN,
                satelliteInterSignalBiasNanos = if (sdk >= 30 && m.hasSatelliteInterSignalBiasNanos()) m.satelliteInterSignalBiasNanos else Double.NaN,
                satelliteInterSignalBiasUncertaintyNanos = if (sdk >= 30 && m.hasSatelliteInterSignalBiasUncertaintyNanos()) m.satelliteInterSignalBiasUncertaintyNanos else Double.NaN,
                codeType = if (sdk >= 29 && m.hasCodeType()) m.codeType else "",
            )
        }

        /**
         * What the log must say about the phone: model, GNSS hardware and its capabilities
         * (Meta lines; GnssLogger writes the same in its header).
         */
        fun capabilities(lm: LocationManager, fullTracking: Boolean): List<Pair<String, String>> {
            val sdk = Build.VERSION.SDK_INT
            val m = mutableListOf<Pair<String, String>>()
            // each item on its own: a vendor (or test) framework that throws on one query
            // must not cost the others
            fun item(key: String, value: () -> String) {
                m += key to try {
                    value()
                } catch (e: RuntimeException) {
                    "unavailable (${e.javaClass.simpleName})"
                }
            }
            item("Device") { "${Build.MANUFACTURER} ${Build.MODEL}" }
            item("DeviceHardware") { "${Build.HARDWARE} / ${Build.BOARD}" }
            item("AndroidApi") { sdk.toString() }
            if (sdk >= 31) item("DeviceSoc") { "${Build.SOC_MANUFACTURER} ${Build.SOC_MODEL}" }
            if (sdk >= 28) {
                item("GnssHardwareModel") { lm.gnssHardwareModelName ?: "unknown" }
                item("GnssYearOfHardware") { lm.gnssYearOfHardware.toString() }
            }
            if (sdk >= 30) item("GnssCapabilities") {
                val c = lm.gnssCapabilities
                val caps = mutableListOf<String>()
                if (sdk >= 31) {
                    if (c.hasMeasurements()) caps += "Measurements"
                    if (c.hasNavigationMessages()) caps += "NavigationMessages"
                    if (c.hasMeasurementCorrections()) caps += "MeasurementCorrections"
                    if (c.hasAntennaInfo()) caps += "AntennaInfo"
                    if (c.hasSatelliteBlocklist()) caps += "SatelliteBlocklist"
                    if (c.hasLowPowerMode()) caps += "LowPowerMode"
                }
                if (sdk >= 33 && c.hasMeasurementCorrectionsForDriving()) caps += "CorrectionsForDriving"
                if (caps.isEmpty()) c.toString() else caps.joinToString(" ")
            }
            item("GnssFullTracking") { if (fullTracking && sdk >= 31) "requested" else "off" }
            return m
        }

        /** GnssLogger's provider names: GPS, FLP (fused), NLP (network). */
        fun providerName(p: String?): String = when (p) {
            LocationManager.GPS_PROVIDER -> "GPS"
            LocationManager.NETWORK_PROVIDER -> "NLP"
            "fused" -> "FLP"
            null -> ""
            else -> p.uppercase()
        }

        fun toFix(l: Location): FixRow {
            val sdk = Build.VERSION.SDK_INT
            return FixRow(
                utcMs = l.time,
                provider = providerName(l.provider),
                latDeg = l.latitude,
                lonDeg = l.longitude,
                altM = if (l.hasAltitude()) l.altitude else Double.NaN,
                speedMps = if (l.hasSpeed()) l.speed.toDouble() else Double.NaN,
                accuracyM = if (l.hasAccuracy()) l.accuracy.toDouble() else Double.NaN,
                bearingDeg = if (l.hasBearing()) l.bearing.toDouble() else Double.NaN,
                speedAccuracyMps = if (sdk >= 26 && l.hasSpeedAccuracy()) l.speedAccuracyMetersPerSecond.toDouble() else Double.NaN,
                bearingAccuracyDeg = if (sdk >= 26 && l.hasBearingAccuracy()) l.bearingAccuracyDegrees.toDouble() else Double.NaN,
                verticalAccuracyM = if (sdk >= 26 && l.hasVerticalAccuracy()) l.verticalAccuracyMeters.toDouble() else Double.NaN,
            )
        }
    }
}
