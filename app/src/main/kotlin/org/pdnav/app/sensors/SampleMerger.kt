package org.pdnav.app.sensors

import org.pdnav.app.nav.SampleBatch
import org.pdnav.app.nav.SampleKind
import org.pdnav.app.nav.SampleSink

/**
 * Merges the sample streams of all sensors (each in time order, delivered late and in
 * batches) into one time-ordered stream for the sinks (navigator, recorder).
 *
 * Sensor callbacks [add] rows; [flush] (called from one thread) hands every row older than
 * `now - holdNs` to the sinks in time order. [holdNs] must cover the sensors' batching
 * latency and the GNSS callback delay, so rows are almost never late; a row that is late
 * anyway (older than what was already emitted) is still emitted, in the next flush, counted
 * in [lateRows] and reported to [onLate] (kind, its time, how far behind) so the session
 * can log and show it. Sinks may be added and removed while running ([setSinks]).
 */
class SampleMerger(
    private val holdNs: Long,
    sinks: List<SampleSink>,
    private val onLate: (kind: Int, tNs: Long, behindNs: Long) -> Unit = { _, _, _ -> },
) {
    private val pendingLock = Any()
    private var pending = SampleBatch(512)
    private var spare = SampleBatch(512)
    private val out = SampleBatch(512)
    private val flushLock = Any()
    private var lastEmittedNs = Long.MIN_VALUE
    @Volatile private var sinks: List<SampleSink> = sinks.toList()
    private val byKind = LongArray(SampleKind.COUNT)

    /** Rows emitted after a later row had already been emitted. */
    @Volatile var lateRows = 0L
        private set

    /** Rows emitted so far. */
    @Volatile var emittedRows = 0L
        private set

    /** Rows emitted so far, per sample kind (index = SampleKind). */
    fun emittedByKind(): LongArray = synchronized(flushLock) { byKind.copyOf() }

    /** Replaces the sinks (taking effect at the next flush). */
    fun setSinks(s: List<SampleSink>) = synchronized(flushLock) { sinks = s.toList() }

    /** Adds rows from a sensor callback (any thread). */
    fun add(fill: (SampleBatch) -> Unit) {
        synchronized(pendingLock) { fill(pending) }
    }

    /**
     * Emits the rows older than nowNs - holdNs (all rows when [all]), in time order. A sink
     * that throws stops the flush (the exception reaches the caller; rows already taken out
     * of the queue are not re-queued: the session ends on such an error).
     */
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
            val t = out.tNs(i)
            if (t < lastEmittedNs) {
                lateRows++
                onLate(out.kind(i), t, lastEmittedNs - t)
            } else {
                lastEmittedNs = t
            }
            byKind[out.kind(i)]++
        }
        emittedRows += out.size
        for (sink in sinks) sink.write(out)
    }

    /** Rows waiting for their hold time. */
    fun pendingRows(): Int = synchronized(pendingLock) { pending.size }
}
