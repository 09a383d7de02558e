package org.pdnav.app.nav

/**
 * io::open_sample_source behind a native handle: reads a recording back as [SampleBatch]es,
 * in time order, for replay in the app and in the host tests: a session log, a GnssLogger log,
 * a Sensor Logger or phyphox export (folder or zip) or a GetSensorData log, the format found
 * from the content (docs/log-format.md section 11). A file no reader recognises is an
 * IOException naming what was expected and what was found.
 */
class NativeLogReader(path: String) : AutoCloseable {
    private val h: NativeHandle
    private val registration: NativeCleaner.Registration

    init {
        NativeBridge.ensureLoaded()
        h = NativeHandle(NativeBridge.readerOpen(path)) { NativeBridge.readerClose(it) }
        registration = NativeCleaner.register(this, h)
    }

    /** Replaces the content of [into] with up to [max] next samples; false at end of input. */
    fun read(into: SampleBatch, max: Int = 512): Boolean = synchronized(h) {
        into.clear()
        into.ensureCapacity(max)
        val n = NativeBridge.readerRead(h.get(), max, into.kinds, into.tNs, into.ints, into.doubles, into.strings, into.bytes)
        into.setFilled(n)
        n > 0
    }

    /** Fraction of the file consumed, 0..1. */
    val progress: Double get() = synchronized(h) { NativeBridge.readerProgress(h.get()) }

    /** Lines read, samples returned and lines skipped so far. */
    val stats: ReadStats
        get() = synchronized(h) {
            val s = NativeBridge.readerStats(h.get())
            ReadStats(s[0], s[1], s[2])
        }

    override fun close() {
        registration.unregister()
        h.close()
    }
}

data class ReadStats(val lines: Long, val samples: Long, val skipped: Long)

/** Replays a whole log through a sink (the in-app replay and the tests). Returns samples fed. */
fun replayLog(path: String, sink: SampleSink, batchSize: Int = 512, onBatch: (NativeLogReader) -> Unit = {}): Long {
    var total = 0L
    NativeLogReader(path).use { reader ->
        val batch = SampleBatch(batchSize)
        while (reader.read(batch, batchSize)) {
            sink.write(batch)
            total += batch.size
            onBatch(reader)
        }
    }
    return total
}
