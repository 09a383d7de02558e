package org.pdnav.app.recording

import org.pdnav.app.nav.NativeLogReader
import org.pdnav.app.nav.NativeNavigator
import org.pdnav.app.nav.NavOutput
import org.pdnav.app.nav.NavigatorConfig
import org.pdnav.app.nav.SampleBatch

/**
 * Replays a recorded session through a fresh navigator on a background thread (the in-app
 * replay). [onProgress] gets the output and the fraction read about every [everyNs] of log
 * time; [onDone] gets the final output, or the error that stopped it.
 */
class ReplayTask(
    private val path: String,
    private val config: NavigatorConfig,
    private val seed: Long,
    private val onProgress: (NavOutput, Double) -> Unit,
    private val onDone: (NavOutput?, Exception?) -> Unit,
    private val everyNs: Long = 1_000_000_000L,
) {
    @Volatile private var cancelled = false
    private var thread: Thread? = null

    fun start() {
        thread = Thread({ run() }, "pdnav-replay").apply { start() }
    }

    fun cancel() {
        cancelled = true
    }

    /** Waits for the replay to end (tests). */
    fun join(timeoutMs: Long) {
        thread?.join(timeoutMs)
    }

    /** The replay itself (also callable synchronously). */
    fun run() {
        try {
            var last: NavOutput? = null
            NativeNavigator(config, seed).use { nav ->
                NativeLogReader(path).use { reader ->
                    val batch = SampleBatch(CHUNK)
                    val one = SampleBatch(1)
                    var nextReportNs = Long.MIN_VALUE
                    while (!cancelled && reader.read(batch, CHUNK)) {
                        // row by row so progress reports fall on the log's own time grid
                        for (i in 0 until batch.size) {
                            one.clear()
                            one.addCopy(batch, i)
                            nav.feed(one)
                            val t = batch.tNs(i)
                            if (nextReportNs == Long.MIN_VALUE) nextReportNs = t + everyNs
                            if (t >= nextReportNs) {
                                nextReportNs = t + everyNs
                                val out = nav.output(200)
                                last = out
                                onProgress(out, reader.progress)
                            }
                        }
                    }
                }
                last = nav.output(200)
            }
            onDone(last, null)
        } catch (e: Exception) {
            onDone(null, e)
        }
    }

    companion object {
        private const val CHUNK = 512
    }
}
