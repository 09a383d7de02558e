package org.pdnav.app.recording

import org.pdnav.app.nav.NativeLogReader
import org.pdnav.app.nav.NativeNavigator
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SessionFeeder
import org.pdnav.app.region.Place
import org.pdnav.app.region.RegionInfo
import org.pdnav.app.region.RegionStore
import org.pdnav.app.walk.RegionalNavigator
import org.pdnav.app.walk.WalkState

/**
 * Replays a recorded session through a fresh navigator on a background thread (owned by
 * NavigationService, so it survives the Activity). Rows go to the native side in batches
 * of [chunk] rows (default [CHUNK]; one JNI call each, not one per row) through a [SessionFeeder], which applies
 * the declared starts the session recorded and scores its `Truth` checkpoints ([checkpoints]).
 * [onProgress] gets the output and the fraction read about every [everyNs] of log time
 * (at batch ends); [onDone] the final output, or the error that stopped it.
 */
class ReplayTask(
    private val path: String,
    private val config: NavigatorConfig,
    private val seed: Long,
    private val onProgress: (NavOutput, Double) -> Unit,
    private val onDone: (NavOutput?, Exception?) -> Unit,
    private val everyNs: Long = 1_000_000_000L,
    private val chunk: Int = CHUNK,
    /** Installed regions: the replay picks the one its walk starts in, as the live session did. */
    private val regions: RegionStore? = null,
    /** Go-to during the replay (bearing, distance and route per step). */
    private val target: Place? = null,
    /** The walker's state at every progress report and at the end. */
    private val onWalk: (WalkState) -> Unit = {},
) {
    @Volatile private var cancelled = false
    private var thread: Thread? = null

    /** Checkpoints scored (after the replay, or so far). */
    @Volatile var checkpoints: List<SessionFeeder.Checkpoint> = emptyList()
        private set

    /** The region the replay opened on (null: the settings' files). */
    @Volatile var region: RegionInfo? = null
        private set

    /** The walker's state at the last report. */
    @Volatile var walk: WalkState? = null
        private set

    /** JNI calls that fed rows (the batching check). */
    @Volatile var feedCalls = 0L
        private set

    fun start() {
        thread = Thread({ run() }, "pdnav-replay").apply { start() }
    }

    fun cancel() {
        cancelled = true
    }

    /** True once [cancel] was called (a rotation must not do that). */
    val isCancelled: Boolean get() = cancelled

    /** Waits for the replay to end (tests). */
    fun join(timeoutMs: Long) {
        thread?.join(timeoutMs)
    }

    /** The replay itself (also callable synchronously). */
    fun run() {
        try {
            var last: NavOutput? = null
            RegionalNavigator(config, seed, regions, null, saveStart = false) { r -> region = r.region }.use { rn ->
                rn.setTarget(target)
                NativeLogReader(path).use { reader ->
                    val batch = SampleBatch(chunk)
                    var nextReportNs = Long.MIN_VALUE
                    while (!cancelled && reader.read(batch, chunk)) {
                        rn.write(batch)
                        feedCalls = rn.feeder?.feedCalls ?: 0L
                        val nav = rn.navigator ?: continue
                        val t = batch.tNs(batch.size - 1)
                        if (nextReportNs == Long.MIN_VALUE) nextReportNs = batch.tNs(0) + everyNs
                        if (t >= nextReportNs) {
                            nextReportNs = t + everyNs
                            val out = nav.output(200)
                            last = out
                            rn.tracker?.let { walk = it.state; onWalk(it.state) }
                            onProgress(out, reader.progress)
                        }
                    }
                }
                rn.finish()
                checkpoints = rn.feeder?.checkpoints ?: emptyList()
                feedCalls = rn.feeder?.feedCalls ?: 0L
                last = rn.navigator?.output(200)
                rn.tracker?.let { walk = it.state; onWalk(it.state) }
            }
            onDone(last, null)
        } catch (e: Exception) {
            onDone(null, e)
        }
    }

    companion object {
        const val CHUNK = 512
    }
}
