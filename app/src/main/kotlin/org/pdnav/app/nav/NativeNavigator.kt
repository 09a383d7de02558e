package org.pdnav.app.nav

/**
 * fusion::Navigator behind an opaque native handle: the one navigation API of the app and
 * of the host tests. Calls are serialised on the handle; [close] is idempotent; any call
 * after close throws IllegalStateException (from the bridge, which sees handle 0). A
 * navigator dropped without close() is released by [NativeCleaner].
 */
class NativeNavigator(config: NavigatorConfig, seed: Long) : AutoCloseable, SampleSink {
    private val h: NativeHandle
    private val registration: NativeCleaner.Registration

    init {
        NativeBridge.ensureLoaded()
        val raw = NativeBridge.navCreate(
            config.mode, config.startLatDeg, config.startLonDeg, config.startSigmaM,
            config.userHeightM, config.userFemale, config.demPath, config.graphPath,
            config.navPaths.toTypedArray(), config.particles, config.terrainPreset, seed,
        )
        h = NativeHandle(raw) { NativeBridge.navClose(it) }
        registration = NativeCleaner.register(this, h)
    }

    val isClosed: Boolean get() = h.isClosed

    /** Feeds every row of [batch] in row order (the caller keeps rows in time order). */
    fun feed(batch: SampleBatch) = synchronized(h) {
        NativeBridge.navFeed(h.get(), batch.size, batch.kinds, batch.tNs, batch.ints, batch.doubles, batch.strings, batch.bytes)
    }

    override fun write(batch: SampleBatch) = feed(batch)

    fun setStart(latDeg: Double, lonDeg: Double, sigmaM: Double, tNs: Long) = synchronized(h) {
        NativeBridge.navSetStart(h.get(), latDeg, lonDeg, sigmaM, tNs)
    }

    fun estimate(): NavEstimate = synchronized(h) { NativeBridge.navEstimate(h.get()) }

    fun output(maxParticles: Int = 200): NavOutput = synchronized(h) { NativeBridge.navOutput(h.get(), maxParticles) }

    /** Samples the core ignored, by reason. */
    fun ignored(): Map<String, Long> = synchronized(h) {
        val flat = NativeBridge.navIgnored(h.get())
        (flat.indices step 2).associate { flat[it] to flat[it + 1].toLong() }
    }

    /** Hand-overs of the fused estimate ("gnss", "gnss-degraded", "route", "terrain", "pdr"), with reasons. */
    fun modeChanges(): List<ModeChange> = synchronized(h) {
        val flat = NativeBridge.navModeChanges(h.get())
        (flat.indices step 4).map { ModeChange(flat[it].toLong(), flat[it + 1], flat[it + 2], flat[it + 3]) }
    }

    /** The steps since the last call, each with its estimate, heading and distance walked. */
    fun takeSteps(): List<StepEstimate> = synchronized(h) {
        val flat = NativeBridge.navTakeSteps(h.get())
        val n = NativeBridge.STEP_DOUBLES
        (flat.indices step n).map {
            StepEstimate(flat[it].toLong(), flat[it + 1], flat[it + 2], flat[it + 3], flat[it + 4], flat[it + 5], flat[it + 6], flat[it + 7])
        }
    }

    /** End of input: the core releases a short walk still held by the step detector. */
    fun finish() = synchronized(h) { NativeBridge.navFinish(h.get()) }

    override fun close() {
        registration.unregister()
        h.close()
    }
}

/** One hand-over of the fused estimate (core: fusion::ModeChange). */
data class ModeChange(val tNs: Long, val from: String, val to: String, val reason: String)

/**
 * One step's estimate (core: fusion::StepEstimate). [latDeg] .. [corrEn] are NaN before the
 * start position is known ([hasPosition] false). [headingRad] clockwise from true north;
 * [distanceM] walked since the session start.
 */
data class StepEstimate(
    val tNs: Long, val latDeg: Double, val lonDeg: Double, val sigmaEastM: Double, val sigmaNorthM: Double,
    val corrEn: Double, val headingRad: Double, val distanceM: Double,
) {
    val hasPosition: Boolean get() = !latDeg.isNaN()
}
