package org.pdnav.app.nav

import java.lang.ref.PhantomReference
import java.lang.ref.ReferenceQueue
import java.util.concurrent.ConcurrentHashMap
import java.util.concurrent.atomic.AtomicLong

/**
 * The native handle of one Kotlin owner ([NativeNavigator], [NativeRecorder],
 * [NativeLogReader]), released exactly once: by the owner's close() or, when the owner was
 * dropped without close(), by [NativeCleaner]. Every native call holds this object's monitor,
 * so a release never races a call in flight.
 */
class NativeHandle internal constructor(value: Long, private val release: (Long) -> Unit) {
    private var value: Long = value

    /** The raw handle (0 once closed: the bridge then throws IllegalStateException). */
    fun get(): Long = synchronized(this) { value }

    val isClosed: Boolean get() = synchronized(this) { value == 0L }

    /** Releases the native object (idempotent). */
    fun close() = synchronized(this) {
        val h = value
        value = 0L
        if (h != 0L) release(h)
    }
}

/**
 * Safety net for handles whose owner was never closed (java.lang.ref.Cleaner is API 33+;
 * the app runs from API 24): a phantom reference per owner, a daemon thread releasing the
 * native object once the owner is unreachable. close() stays the normal path; [released]
 * counts what the net caught (a leak in the app, logged by the owners' users).
 */
object NativeCleaner {
    private val queue = ReferenceQueue<Any>()
    private val live: MutableSet<Ref> = ConcurrentHashMap.newKeySet()
    private val releasedCount = AtomicLong()

    /** Handles released by the safety net (owners garbage-collected without close()). */
    val released: Long get() = releasedCount.get()

    internal class Ref(owner: Any, val handle: NativeHandle, q: ReferenceQueue<Any>) : PhantomReference<Any>(owner, q)

    /** What an owner keeps to unregister itself on close(). */
    class Registration internal constructor(private val ref: Ref?) {
        fun unregister() {
            if (ref != null) {
                live.remove(ref)
                ref.clear()
            }
        }
    }

    init {
        Thread({
            while (true) {
                val r = try {
                    queue.remove() as Ref
                } catch (e: InterruptedException) {
                    continue
                }
                if (live.remove(r) && !r.handle.isClosed) {
                    releasedCount.incrementAndGet()
                    try {
                        r.handle.close()
                    } catch (e: RuntimeException) {
                        // nothing to report to: the owner is gone; the count says it happened
                    }
                }
            }
        }, "pdnav-native-cleaner").apply {
            isDaemon = true
            start()
        }
    }

    /** Releases [handle] when [owner] becomes unreachable without having closed it. */
    fun register(owner: Any, handle: NativeHandle): Registration {
        val r = Ref(owner, handle, queue)
        live += r
        return Registration(r)
    }
}
