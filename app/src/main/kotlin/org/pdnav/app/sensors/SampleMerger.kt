package org.pdnav.app.sensors

import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleSink

/**
 * Merges the sample streams of all sensors (each in time order, delivered late and in
 * batches) into one time-ordered stream for the sinks (navigator, recorder).
 *
 * Sensor callbacks [add] rows; [flush] (called periodically on one thread) hands every row
 * older than `now - holdNs` to the sinks in time order. [holdNs] must cover the sensors'
 * batching latency and the GNSS callback delay, so rows are almost never late; a row that
 * is late anyway (older than what was already emitted) is still emitted, in the next flush,
 * and counted in [lateRows] (each sensor's own order is always kept).
 */
class SampleMerger(
    private val holdNs: Long,
    private val sinks: List<SampleSink>,
) {
    private val pendingLock = Any()
    private var pending = SampleBatch(512)
    private var spare = SampleBatch(512)
    private val out = SampleBatch(512)
    private val flushLock = Any()
    private var lastEmittedNs = Long.MIN_VALUE

    /** Rows emitted after a later row had already been emitted. */
    @Volatile var lateRows = 0L
        private set

    /** Rows emitted so far. */
    @Volatile var emittedRows = 0L
        private set

    /** Adds rows from a sensor callback (any thread). */
    fun add(fill: (SampleBatch) -> Unit) {
        synchronized(pendingLock) { fill(pending) }
    }

    /** Emits the rows older than nowNs - holdNs (all rows when [all]), in time order. */
    fun flush(nowNs: Long, all: Boolean = false) = synchronized(flushLock) {
        out.clear()
        synchronized(pendingLock) {
            val cutoff = if (all) Long.MAX_VALUE else nowNs - holdNs
            val keep = spare
            keep.clear()
            for (i in pending.timeOrder()) {
                if (pending.tNs(i) <= cutoff) out.addCopy(pending, i) else keep.addCopy(pending, i)
            }
            spare = pending
            pending = keep
        }
        if (out.size == 0) return@synchronized
        for (i in 0 until out.size) {
            if (out.tNs(i) < lastEmittedNs) lateRows++ else lastEmittedNs = out.tNs(i)
        }
        emittedRows += out.size
        for (sink in sinks) sink.write(out)
    }

    /** Rows waiting for their hold time. */
    fun pendingRows(): Int = synchronized(pendingLock) { pending.size }
}
