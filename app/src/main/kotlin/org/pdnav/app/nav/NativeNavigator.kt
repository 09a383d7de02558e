package org.pdnav.app.nav

/**
 * fusion::Navigator behind an opaque native handle: the one navigation API of the app and
 * of the host tests. Calls are serialised on this object; [close] is idempotent; any call
 * after close throws IllegalStateException (from the bridge, which sees handle 0).
 */
class NativeNavigator(config: NavigatorConfig, seed: Long) : AutoCloseable, SampleSink {
    private val lock = Any()
    private var handle: Long

    init {
        NativeBridge.ensureLoaded()
        handle = NativeBridge.navCreate(
            config.mode, config.startLatDeg, config.startLonDeg, config.startSigmaM,
            config.userHeightM, config.userFemale, config.demPath, config.graphPath,
            config.navPaths.toTypedArray(), config.particles, config.terrainPreset, seed,
        )
    }

    val isClosed: Boolean get() = synchronized(lock) { handle == 0L }

    /** Feeds every row of [batch] in row order (the caller keeps rows in time order). */
    fun feed(batch: SampleBatch) = synchronized(lock) {
        NativeBridge.navFeed(handle, batch.size, batch.kinds, batch.tNs, batch.ints, batch.doubles, batch.strings, batch.bytes)
    }

    override fun write(batch: SampleBatch) = feed(batch)

    fun setStart(latDeg: Double, lonDeg: Double, sigmaM: Double, tNs: Long) = synchronized(lock) {
        NativeBridge.navSetStart(handle, latDeg, lonDeg, sigmaM, tNs)
    }

    fun estimate(): NavEstimate = synchronized(lock) { NativeBridge.navEstimate(handle) }

    fun output(maxParticles: Int = 200): NavOutput = synchronized(lock) { NativeBridge.navOutput(handle, maxParticles) }

    /** Samples the core ignored, by reason. */
    fun ignored(): Map<String, Long> = synchronized(lock) {
        val flat = NativeBridge.navIgnored(handle)
        (flat.indices step 2).associate { flat[it] to flat[it + 1].toLong() }
    }

    /** Hand-overs of the fused estimate ("gnss", "gnss-degraded", "route", "terrain", "pdr"), with reasons. */
    fun modeChanges(): List<ModeChange> = synchronized(lock) {
        val flat = NativeBridge.navModeChanges(handle)
        (flat.indices step 4).map { ModeChange(flat[it].toLong(), flat[it + 1], flat[it + 2], flat[it + 3]) }
    }

    override fun close() = synchronized(lock) {
        val h = handle
        handle = 0L
        if (h != 0L) NativeBridge.navClose(h)
    }
}

/** One hand-over of the fused estimate (core: fusion::ModeChange). */
data class ModeChange(val tNs: Long, val from: String, val to: String, val reason: String)
