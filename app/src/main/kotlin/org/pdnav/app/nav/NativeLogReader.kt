package org.pdnav.app.nav

/**
 * io::LogReader behind a native handle: reads a session log (or a GnssLogger log) back as
 * [SampleBatch]es, in file order, for replay in the app and in the host tests.
 */
class NativeLogReader(path: String) : AutoCloseable {
    private val lock = Any()
    private var handle: Long

    init {
        NativeBridge.ensureLoaded()
        handle = NativeBridge.readerOpen(path)
    }

    /** Replaces the content of [into] with up to [max] next samples; false at end of input. */
    fun read(into: SampleBatch, max: Int = 512): Boolean = synchronized(lock) {
        into.clear()
        into.ensureCapacity(max)
        val n = NativeBridge.readerRead(handle, max, into.kinds, into.tNs, into.ints, into.doubles, into.strings, into.bytes)
        into.setFilled(n)
        n > 0
    }

    /** Fraction of the file consumed, 0..1. */
    val progress: Double get() = synchronized(lock) { NativeBridge.readerProgress(handle) }

    /** Lines read, samples returned and lines skipped so far. */
    val stats: ReadStats
        get() = synchronized(lock) {
            val s = NativeBridge.readerStats(handle)
            ReadStats(s[0], s[1], s[2])
        }

    override fun close() = synchronized(lock) {
        val h = handle
        handle = 0L
        if (h != 0L) NativeBridge.readerClose(h)
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
