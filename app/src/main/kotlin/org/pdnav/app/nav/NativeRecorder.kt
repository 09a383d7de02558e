package org.pdnav.app.nav

/**
 * io::LogWriter behind a native handle: writes the session log (docs/log-format.md).
 * Crash-safe by the writer's design: whole lines reach the OS at least every
 * [flushIntervalNs] of sample time and on [flush]/[close]. Calls are serialised; [close] is
 * idempotent; calls after close throw IllegalStateException. A recorder dropped without
 * close() is closed (its lines handed to the OS) by [NativeCleaner].
 */
class NativeRecorder(
    path: String,
    device: String = "",
    flushIntervalNs: Long = 1_000_000_000L,
    fsync: Boolean = false,
) : AutoCloseable, SampleSink {
    private val h: NativeHandle
    private val registration: NativeCleaner.Registration

    init {
        NativeBridge.ensureLoaded()
        h = NativeHandle(NativeBridge.recOpen(path, device, flushIntervalNs, fsync)) { NativeBridge.recClose(it) }
        registration = NativeCleaner.register(this, h)
    }

    override fun write(batch: SampleBatch) = synchronized(h) {
        NativeBridge.recWrite(h.get(), batch.size, batch.kinds, batch.tNs, batch.ints, batch.doubles, batch.strings, batch.bytes)
    }

    fun flush() = synchronized(h) { NativeBridge.recFlush(h.get()) }

    val linesWritten: Long get() = synchronized(h) { NativeBridge.recLines(h.get()) }

    val isClosed: Boolean get() = h.isClosed

    override fun close() {
        registration.unregister()
        h.close()
    }
}
