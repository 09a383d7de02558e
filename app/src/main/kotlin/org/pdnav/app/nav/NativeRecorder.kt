package org.pdnav.app.nav

/**
 * io::LogWriter behind a native handle: writes the session log (docs/log-format.md).
 * Crash-safe by the writer's design: whole lines reach the OS at least every
 * [flushIntervalNs] of sample time and on [flush]/[close]. Calls are serialised; [close] is
 * idempotent; calls after close throw IllegalStateException.
 */
class NativeRecorder(
    path: String,
    device: String = "",
    flushIntervalNs: Long = 1_000_000_000L,
    fsync: Boolean = false,
) : AutoCloseable, SampleSink {
    private val lock = Any()
    private var handle: Long

    init {
        NativeBridge.ensureLoaded()
        handle = NativeBridge.recOpen(path, device, flushIntervalNs, fsync)
    }

    override fun write(batch: SampleBatch) = synchronized(lock) {
        NativeBridge.recWrite(handle, batch.size, batch.kinds, batch.tNs, batch.ints, batch.doubles, batch.strings, batch.bytes)
    }

    fun flush() = synchronized(lock) { NativeBridge.recFlush(handle) }

    val linesWritten: Long get() = synchronized(lock) { NativeBridge.recLines(handle) }

    override fun close() = synchronized(lock) {
        val h = handle
        handle = 0L
        if (h != 0L) NativeBridge.recClose(h)
    }
}
